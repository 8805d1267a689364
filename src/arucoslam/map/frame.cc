#include "arucoslam/map/frame.h"

#include <stdexcept>

namespace arucoslam {

Eigen::Vector2d FeatureView::UndistortedPixel(const OrbFeatures& features,
                                              const CameraModel& camera, int index) {
  const Eigen::Vector2d& normalised = features.undistorted.at(index);
  return {camera.fx * normalised.x() + camera.cx, camera.fy * normalised.y() + camera.cy};
}

double FeatureView::SigmaPx(const OrbFeatures& features, int index) {
  const int octave = features.keypoints.at(index).octave;
  if (octave < 0 || octave >= static_cast<int>(features.pyramid.scales.size())) return 1.0;
  return features.pyramid.scales[octave];
}

void Frame::ResetMatches() {
  map_point_ids.assign(features.size(), MapPointId());
  outliers.assign(features.size(), false);
}

int Frame::NumMatched() const {
  int count = 0;
  for (std::size_t i = 0; i < map_point_ids.size(); ++i) {
    if (map_point_ids[i].IsValid() && !(i < outliers.size() && outliers[i])) ++count;
  }
  return count;
}

Keyframe Keyframe::FromFrame(const Frame& frame) {
  if (!frame.cam_from_world) throw std::logic_error("Keyframe::FromFrame: frame has no pose");
  Keyframe keyframe;
  keyframe.frame_id = frame.id;
  keyframe.timestamp_s = frame.timestamp_s;
  keyframe.camera = frame.camera;
  keyframe.features = frame.features;
  keyframe.cam_from_world = *frame.cam_from_world;
  keyframe.map_point_ids.assign(frame.features.size(), MapPointId());
  for (std::size_t i = 0; i < frame.map_point_ids.size() && i < frame.features.size(); ++i) {
    const bool outlier = i < frame.outliers.size() && frame.outliers[i];
    if (!outlier) keyframe.map_point_ids[i] = frame.map_point_ids[i];
  }
  keyframe.markers = frame.markers;
  return keyframe;
}

int Keyframe::NumMapPoints() const {
  int count = 0;
  for (const MapPointId& id : map_point_ids) count += id.IsValid() ? 1 : 0;
  return count;
}

}  // namespace arucoslam
