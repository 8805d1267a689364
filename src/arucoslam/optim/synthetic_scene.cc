#include "arucoslam/optim/synthetic_scene.h"

#include <random>

#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool SyntheticSceneOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("num_poses", num_poses, 1);
  check.AtLeast("num_points", num_points, 1);
  check.AtLeast("baseline_m", baseline_m, 0.0);
  check.Above("min_depth_m", min_depth_m, 0.0);
  check.Above("max_depth_m", max_depth_m, min_depth_m, "min_depth_m");
  check.AtLeast("noise_px", noise_px, 0.0);
  check.Above("image_width", image_width, 0);
  check.Above("image_height", image_height, 0);
  check.Above("focal_px", focal_px, 0.0);
  return check.ok();
}

BundleAdjustmentProblem MakeSyntheticScene(const SyntheticSceneOptions& options) {
  std::mt19937 random(options.seed);
  BundleAdjustmentProblem problem;
  problem.intrinsics = {options.focal_px, options.focal_px, 0.5 * (options.image_width - 1),
                        0.5 * (options.image_height - 1)};
  // Cameras look along world +z (camera axes = world axes), with a small yaw and roll
  // that vary along the line so that poses are not all parallel.
  for (int i = 0; i < options.num_poses; ++i) {
    const Eigen::Vector3d position(options.baseline_m * i, 0.02 * (i % 3), 0.0);
    const Eigen::Quaterniond world_from_cam_rotation =
        Eigen::AngleAxisd(0.02 * i - 0.1, Eigen::Vector3d::UnitY()) *
        Eigen::AngleAxisd(0.01 * (i % 4), Eigen::Vector3d::UnitZ());
    const Rigid3 world_from_cam(world_from_cam_rotation, position);
    problem.poses.push_back({world_from_cam.Inverse(), false});
  }
  // Points in the view frustum of the middle of the line.
  const double span = options.baseline_m * (options.num_poses - 1);
  std::uniform_real_distribution<double> depth(options.min_depth_m, options.max_depth_m);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double half_x = 0.5 * options.image_width / options.focal_px;
  const double half_y = 0.5 * options.image_height / options.focal_px;
  for (int j = 0; j < options.num_points; ++j) {
    const double z = depth(random);
    const Eigen::Vector3d p(0.5 * span + unit(random) * half_x * z, unit(random) * half_y * z, z);
    problem.points.push_back({p, false});
  }
  std::normal_distribution<double> noise(0.0, options.noise_px > 0.0 ? options.noise_px : 1.0);
  for (std::size_t i = 0; i < problem.poses.size(); ++i) {
    const Rigid3& cam_from_world = problem.poses[i].cam_from_world;
    for (std::size_t j = 0; j < problem.points.size(); ++j) {
      const Eigen::Vector3d p_in_cam = cam_from_world * problem.points[j].p_in_world;
      if (p_in_cam.z() < 0.1) continue;
      Eigen::Vector2d pixel = problem.intrinsics.ToPixel(p_in_cam.head<2>() / p_in_cam.z());
      if (pixel.x() < 0.0 || pixel.y() < 0.0 || pixel.x() > options.image_width - 1 ||
          pixel.y() > options.image_height - 1) {
        continue;
      }
      if (options.noise_px > 0.0) pixel += Eigen::Vector2d(noise(random), noise(random));
      problem.observations.push_back({i, j, pixel, 1.0});
    }
  }
  return problem;
}

}  // namespace arucoslam
