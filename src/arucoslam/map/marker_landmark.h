// MarkerLandmark: one ArUco marker in the map (side, world_from_marker, fixed or estimated,
// the keyframes that saw it with their corners); MarkerLandmarks: the container keyed by id.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <map>
#include <string>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/map/ids.h"
#include "arucoslam/markers/marker_map.h"

namespace arucoslam {

struct MarkerLandmark {
  MarkerId id;
  double size = 0.0;  // side of the black square, metres
  Rigid3 world_from_marker;
  // True for a marker of the known map (markers.json, fixed: true): never moved by the
  // SLAM. False for a marker the SLAM estimates (mapped online or fixed: false in the file).
  bool fixed = false;
  // Keyframes that saw the marker and the four corners they saw, in distorted pixels of
  // that keyframe's image, OpenCV order (as MarkerObservation::corners_px).
  std::map<KeyframeId, std::array<Eigen::Vector2d, 4>> observations;

  std::array<Eigen::Vector3d, 4> CornersInMarker() const;  // OpenCV order
  std::array<Eigen::Vector3d, 4> CornersInWorld() const;
  MarkerInfo ToMarkerInfo() const;
  // A landmark with the pose, size and fixed flag of `info` and no observations.
  static MarkerLandmark FromMarkerInfo(const MarkerInfo& info);
};

// The markers of one map. Plain data like MapData (not thread-safe on its own): the Map that
// holds it guards it with its lock. Erasing a keyframe must be forwarded (EraseKeyframe).
class MarkerLandmarks {
 public:
  // Stores a landmark (its observations included). False, changing nothing, when the id is
  // invalid, already present, or the size is not positive.
  bool Add(MarkerLandmark landmark);
  // Records that `keyframe` saw marker `id` at `corners_px` (replacing an earlier record of
  // the same keyframe). False when the marker is unknown.
  bool AddObservation(MarkerId id, KeyframeId keyframe,
                      const std::array<Eigen::Vector2d, 4>& corners_px);
  // Drops every observation by `keyframe`; returns how many markers lost one.
  int EraseKeyframe(KeyframeId keyframe);
  // Removes a marker; false when absent.
  bool Erase(MarkerId id);
  // Sets the pose of a non-fixed marker; false for an unknown or fixed marker.
  bool SetPose(MarkerId id, const Rigid3& world_from_marker);

  const MarkerLandmark* Find(MarkerId id) const;
  bool Contains(MarkerId id) const { return landmarks_.count(id) > 0; }
  const std::map<MarkerId, MarkerLandmark>& landmarks() const { return landmarks_; }
  std::size_t size() const { return landmarks_.size(); }
  bool empty() const { return landmarks_.empty(); }

  // The known map as landmarks (fixed as each marker's `fixed` flag says).
  static MarkerLandmarks FromMarkerMap(const MarkerMap& map);
  // Every landmark as a MarkerMap entry (fixed flags kept), for WriteMarkerMapJson.
  MarkerMap ToMarkerMap(const std::string& dictionary) const;

 private:
  std::map<MarkerId, MarkerLandmark> landmarks_;
};

}  // namespace arucoslam
