// MarkerMapper: maps markers that the known marker map lacks, online: initialised from IPPE
// composed with the keyframe pose (a second view settles ambiguous ones), refined by BA.
#pragma once

#include <map>
#include <vector>

#include "arucoslam/map/frame.h"
#include "arucoslam/map/map_data.h"
#include "arucoslam/map/marker_landmark.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/markers/marker_pose.h"
#include "arucoslam/optim/marker_bundle_adjustment.h"

namespace arucoslam {

struct MarkerMapperOptions {
  // Side of the markers absent from the known map, metres. 0: the side of the known map's
  // first marker (no unknown marker is mapped when the known map is empty too).
  double unknown_marker_size_m = 0.0;
  // False: only the known markers' observations are recorded, none is mapped.
  bool map_unknown = true;
  // IPPE ambiguity test of a single view (see marker_pose.h).
  MarkerPoseOptions marker_pose;
  // A first view whose best IPPE solution reprojects worse than this (RMS, pixels) is not
  // used to initialise (blurred or partly occluded corners).
  double max_initial_rms_px = 2.0;
  // Views an ambiguous marker may collect before it is initialised from the candidate
  // that explains all of them best (at least 2: the second view settles the ambiguity).
  int views_to_resolve_ambiguity = 2;
  // Corner noise given to the bundle adjustment, pixels.
  double corner_sigma_px = 1.0;
  MarkerBundleAdjustmentOptions bundle_adjustment;

  bool Check() const {
    return unknown_marker_size_m >= 0.0 && marker_pose.Check() && max_initial_rms_px > 0.0 &&
           views_to_resolve_ambiguity >= 2 && corner_sigma_px > 0.0 && bundle_adjustment.Check();
  }
};

class MarkerMapper {
 public:
  // `known`: the markers.json map; its markers are kept as they are (fixed or not).
  explicit MarkerMapper(const MarkerMap& known, const MarkerMapperOptions& options = {});

  // Records the markers a keyframe saw (corners in distorted pixels of `camera`) at its
  // current pose estimate in the world. Returns the ids of markers initialised by this view.
  std::vector<MarkerId> AddKeyframe(KeyframeId keyframe, const Rigid3& cam_from_world,
                                    const CameraModel& camera,
                                    const std::vector<MarkerObservation>& markers);
  // Forgets a keyframe (culled by the local mapper).
  void EraseKeyframe(KeyframeId keyframe);
  // Takes the current pose of every recorded keyframe from `map` (optimisation moved them)
  // and forgets the ones `map` no longer holds (culled, or the map was reset).
  void SyncKeyframes(const MapData& map);

  // Bundle adjustment of every keyframe and point of `map` with the marker observations:
  // known markers fixed, mapped ones estimated. Poses, points and marker poses are written
  // back on success (the keyframe poses this mapper keeps too). One camera for all.
  MarkerBundleAdjustmentSummary Refine(MapData* map);
  // Refines only the mapped markers against the recorded keyframe poses (held fixed).
  MarkerBundleAdjustmentSummary RefineMarkers();

  const MarkerLandmarks& landmarks() const { return landmarks_; }
  // For optimisations that estimate the mapped markers with the keyframes (local BA).
  MarkerLandmarks* mutable_landmarks() { return &landmarks_; }
  bool Records(KeyframeId keyframe) const { return keyframes_.count(keyframe) > 0; }
  // Known and mapped markers (mapped ones with fixed: false); pending ones are left out.
  MarkerMap ToMarkerMap() const;
  int NumPending() const { return static_cast<int>(pending_.size()); }

 private:
  struct KeyframeRecord {
    Rigid3 cam_from_world;
    CameraModel camera;
  };
  struct View {
    KeyframeId keyframe;
    std::array<Eigen::Vector2d, 4> corners_px;
    MarkerPose pose;  // IPPE in that view
  };

  void Observe(KeyframeId keyframe, const MarkerObservation& observation,
               std::vector<MarkerId>* initialised);
  // Initialises a pending marker when its views allow it; true when it did.
  bool TryInitialise(MarkerId id);
  double ViewsSquaredError(const std::vector<View>& views, const Rigid3& world_from_marker) const;
  MarkerBundleAdjustmentProblem BuildProblem(const MapData* map, std::vector<KeyframeId>* poses,
                                             std::vector<MapPointId>* points,
                                             std::vector<MarkerId>* markers) const;

  MarkerMapperOptions options_;
  std::string dictionary_;
  double unknown_size_ = 0.0;
  MarkerLandmarks landmarks_;
  std::map<KeyframeId, KeyframeRecord> keyframes_;
  std::map<MarkerId, std::vector<View>> pending_;
};

}  // namespace arucoslam
