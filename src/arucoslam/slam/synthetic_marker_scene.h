// Test scene of the SLAM and pipeline tests: a camera moving sideways past a synthetic point
// cloud (SyntheticFeatureScene) and a row of known markers on a wall.
#pragma once

#include <array>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "arucoslam/markers/marker_map.h"
#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/pose_consistency.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/slam/synthetic_features.h"

namespace arucoslam::test_scene {

inline constexpr double kSceneDt = 0.05;  // 20 Hz

inline CameraModel SceneCamera() {
  return PinholeCamera(640, 480, 500.0);
}

// Sideways (0.6 m/s), weaving, slowly turning camera, metres.
inline Rigid3 SceneWorldFromCam(int t) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.003 * t, Eigen::Vector3d::UnitY())),
                Eigen::Vector3d(0.03 * t, 0.2 * std::sin(t / 15.0), 0.003 * t));
}

inline int SceneFrameOf(double timestamp_s) {
  return static_cast<int>(std::lround(timestamp_s / kSceneDt));
}

// A row of markers (sides `size`, 0.5 m apart) on a wall 3 m in front of the start.
inline MarkerMap SceneMarkers(int count = 11, double size = 0.4) {
  MarkerMap map;
  map.dictionary = "DICT_4X4_50";
  const Eigen::Quaterniond facing(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  for (int i = 0; i < count; ++i) {
    MarkerInfo info;
    info.id = i;
    info.size = size;
    info.world_from_marker = Rigid3(facing, Eigen::Vector3d(-1.0 + 0.5 * i, 0.0, 3.0));
    map.markers[i] = info;
  }
  return map;
}

// Detections of the markers fully in view, corners with Gaussian noise of 0.3 px.
inline std::vector<MarkerDetection> SceneDetections(const MarkerMap& map,
                                                    const CameraModel& camera,
                                                    const Rigid3& cam_from_world,
                                                    std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, 0.3);
  std::vector<MarkerDetection> detections;
  for (const auto& [id, info] : map.markers) {
    MarkerDetection detection;
    detection.id = info.id;
    bool visible = true;
    const std::array<Eigen::Vector3d, 4> corners = info.CornersInWorld();
    for (int c = 0; c < 4; ++c) {
      const std::optional<Eigen::Vector2d> pixel = camera.Project(cam_from_world * corners[c]);
      if (!pixel || !camera.InImage(*pixel, 5.0)) {
        visible = false;
        break;
      }
      detection.corners[c] = *pixel + Eigen::Vector2d(noise(rng), noise(rng));
    }
    if (visible) detections.push_back(detection);
  }
  return detections;
}

// Position RMSE against SceneWorldFromCam, no alignment, metres (0 for no poses).
inline double SceneAbsoluteRmse(const std::vector<StampedPose>& trajectory) {
  if (trajectory.empty()) return 0.0;
  double sum = 0.0;
  for (const StampedPose& pose : trajectory) {
    sum += (pose.world_from_cam.translation -
            SceneWorldFromCam(SceneFrameOf(pose.timestamp_s)).translation).squaredNorm();
  }
  return std::sqrt(sum / trajectory.size());
}

}  // namespace arucoslam::test_scene
