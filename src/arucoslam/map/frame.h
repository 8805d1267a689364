// Frame: one image as tracking sees it (features, camera, estimated pose, which map point each
// keypoint matched, detected markers). Keyframe: a Frame kept in the Map, with its observations.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <vector>

#include "arucoslam/feature/keypoints.h"
#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/map/ids.h"
#include "arucoslam/markers/detector.h"

namespace arucoslam {

// A marker seen in an image: its id and its four corners (distorted pixels, OpenCV order:
// top-left, top-right, bottom-right, bottom-left), as the System's marker handling records it.
struct MarkerObservation {
  MarkerId marker_id;
  std::array<Eigen::Vector2d, 4> corners_px{};

  // The same as a detection, for the marker pose and camera location functions.
  MarkerDetection AsDetection() const { return {marker_id.value, corners_px}; }
};

// Feature access shared by Frame and Keyframe.
struct FeatureView {
  // Undistorted pixel of keypoint `index` (pinhole K applied to the undistorted normalised
  // coordinates), the coordinates every optimisation works in.
  static Eigen::Vector2d UndistortedPixel(const OrbFeatures& features, const CameraModel& camera,
                                          int index);
  // Keypoint noise in pixels at its pyramid level (1 at level 0, 1.2^l above).
  static double SigmaPx(const OrbFeatures& features, int index);
};

struct Frame {
  FrameId id;
  double timestamp_s = 0.0;
  CameraModel camera;
  OrbFeatures features;                  // `undistorted` must be filled (feature/undistort.h)
  std::optional<Rigid3> cam_from_world;  // set once tracking found a pose
  // One entry per keypoint: the matched map point, or an invalid id.
  std::vector<MapPointId> map_point_ids;
  // One flag per keypoint: the match was rejected as an outlier by pose optimisation.
  std::vector<bool> outliers;
  std::vector<MarkerObservation> markers;

  // Sizes map_point_ids and outliers to the number of keypoints (all unmatched).
  void ResetMatches();
  int NumMatched() const;  // valid map point ids that are not outliers
  Eigen::Vector2d UndistortedPixel(int index) const {
    return FeatureView::UndistortedPixel(features, camera, index);
  }
  double SigmaPx(int index) const { return FeatureView::SigmaPx(features, index); }
};

struct Keyframe {
  KeyframeId id;     // assigned by Map::AddKeyframe
  FrameId frame_id;  // the frame it was made from
  double timestamp_s = 0.0;
  CameraModel camera;
  OrbFeatures features;
  Rigid3 cam_from_world;
  // One entry per keypoint: the map point it observes, or an invalid id. Kept consistent
  // with MapPoint::observations by the Map; read it, do not edit it behind the Map's back.
  std::vector<MapPointId> map_point_ids;
  std::vector<MarkerObservation> markers;

  // A keyframe from a tracked frame: features, pose and the non-outlier matches.
  // The frame must have a pose.
  static Keyframe FromFrame(const Frame& frame);

  Eigen::Vector3d CameraCenter() const { return cam_from_world.Inverse().translation; }
  int NumMapPoints() const;
  Eigen::Vector2d UndistortedPixel(int index) const {
    return FeatureView::UndistortedPixel(features, camera, index);
  }
  double SigmaPx(int index) const { return FeatureView::SigmaPx(features, index); }
};

}  // namespace arucoslam
