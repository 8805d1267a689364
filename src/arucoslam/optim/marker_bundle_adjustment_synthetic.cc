#include "arucoslam/optim/marker_bundle_adjustment_synthetic.h"

#include <cmath>
#include <random>

#include "arucoslam/markers/marker_pose.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// Camera looking along world +x turned by `yaw` about world z (OpenCV camera axes).
Rigid3 CameraPose(const Eigen::Vector3d& position, double yaw) {
  Eigen::Matrix3d world_from_cam_rotation;
  world_from_cam_rotation.col(0) = Eigen::Vector3d(std::sin(yaw), -std::cos(yaw), 0.0);  // right
  world_from_cam_rotation.col(1) = Eigen::Vector3d(0.0, 0.0, -1.0);                      // down
  world_from_cam_rotation.col(2) = Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);   // ahead
  return Rigid3(world_from_cam_rotation, position).Inverse();
}

// A marker facing world -x (towards the approaching camera), turned by `yaw` about world z.
Rigid3 FacingMarkerPose(const Eigen::Vector3d& position, double yaw) {
  Eigen::Matrix3d rotation;
  rotation.col(0) = Eigen::Vector3d(std::sin(yaw), -std::cos(yaw), 0.0);   // right, as seen
  rotation.col(1) = Eigen::Vector3d(0.0, 0.0, 1.0);                        // up
  rotation.col(2) = Eigen::Vector3d(-std::cos(yaw), -std::sin(yaw), 0.0);  // out of the face
  return Rigid3(rotation, position);
}

}  // namespace

bool SyntheticMarkerSceneOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("num_poses", num_poses, 2);
  check.Above("path_length_m", path_length_m, 0.0);
  check.AtLeast("num_points", num_points, 0);
  check.AtLeast("num_markers", num_markers, 0);
  check.Above("marker_size_m", marker_size_m, 0.0);
  check.Above("max_marker_distance_m", max_marker_distance_m, 0.0);
  check.AtLeast("noise_px", noise_px, 0.0);
  check.AtLeast("corner_noise_px", corner_noise_px, 0.0);
  check.Above("image_width", image_width, 0);
  check.Above("image_height", image_height, 0);
  check.Above("focal_px", focal_px, 0.0);
  return check.ok();
}

MarkerBundleAdjustmentProblem MakeSyntheticMarkerScene(const SyntheticMarkerSceneOptions& options) {
  MarkerBundleAdjustmentProblem scene;
  auto& keypoints = scene.keypoints;
  keypoints.intrinsics = {options.focal_px, options.focal_px, 0.5 * (options.image_width - 1),
                          0.5 * (options.image_height - 1)};
  std::mt19937 random(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double length = options.path_length_m;
  for (int i = 0; i < options.num_poses; ++i) {
    const double t = static_cast<double>(i) / (options.num_poses - 1);
    const Eigen::Vector3d position(t * length, 0.3 * std::sin(3.0 * t),
                                   1.0 + options.height_wobble_m * std::sin(7 * t));
    keypoints.poses.push_back({CameraPose(position, 0.12 * std::sin(5.0 * t)), false});
  }
  for (int i = 0; i < options.num_points; ++i) {
    const Eigen::Vector3d p(2.0 + (length + 10.0) * uniform(random), -4.0 + 8.0 * uniform(random),
                            3.0 * uniform(random));
    keypoints.points.push_back({p, false});
  }
  for (int i = 0; i < options.num_markers; ++i) {
    const double x = 3.0 + (length + 4.0) * i / std::max(1, options.num_markers - 1);
    const Eigen::Vector3d position(x, (i % 2 == 0 ? 1.0 : -1.0) * 0.8, 1.0 + 0.2 * (i % 3));
    scene.markers.push_back(
        {FacingMarkerPose(position, 0.3 * (i % 2 == 0 ? -1 : 1)), options.marker_size_m, true});
  }
  const auto in_image = [&](const Eigen::Vector2d& pixel) {
    return pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() <= options.image_width - 1 &&
           pixel.y() <= options.image_height - 1;
  };
  for (std::size_t pose = 0; pose < keypoints.poses.size(); ++pose) {
    const Rigid3& cam_from_world = keypoints.poses[pose].cam_from_world;
    for (std::size_t point = 0; point < keypoints.points.size(); ++point) {
      const Eigen::Vector3d p_in_cam = cam_from_world * keypoints.points[point].p_in_world;
      if (p_in_cam.z() < 0.5) continue;
      const Eigen::Vector2d pixel = keypoints.intrinsics.ToPixel(p_in_cam.hnormalized());
      if (!in_image(pixel)) continue;
      const Eigen::Vector2d noise(normal(random), normal(random));
      keypoints.observations.push_back({pose, point, pixel + options.noise_px * noise, 1.0});
    }
    for (std::size_t m = 0; m < scene.markers.size(); ++m) {
      const auto& marker = scene.markers[m];
      const Rigid3 cam_from_marker = cam_from_world * marker.world_from_marker;
      // Facing the camera: the marker's z axis points towards the camera centre.
      const Eigen::Vector3d centre = cam_from_marker.translation;
      if (centre.z() < 0.5 || centre.norm() > options.max_marker_distance_m ||
          (cam_from_marker.rotation * Eigen::Vector3d::UnitZ()).dot(centre) > 0.0) {
        continue;
      }
      MarkerBundleAdjustmentProblem::CornerObservation observation;
      observation.pose_index = pose;
      observation.marker_index = m;
      bool visible = true;
      const auto corners = SquareCorners(marker.size);
      for (int c = 0; c < 4; ++c) {
        const Eigen::Vector3d p_in_cam = cam_from_marker * corners[c];
        const Eigen::Vector2d pixel = keypoints.intrinsics.ToPixel(p_in_cam.hnormalized());
        visible = visible && p_in_cam.z() > 0.1 && in_image(pixel);
        observation.corners_px[c] =
            pixel + options.corner_noise_px * Eigen::Vector2d(normal(random), normal(random));
      }
      if (visible) scene.marker_observations.push_back(observation);
    }
  }
  return scene;
}

}  // namespace arucoslam
