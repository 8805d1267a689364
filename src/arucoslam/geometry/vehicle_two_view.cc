#include "arucoslam/geometry/vehicle_two_view.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "arucoslam/geometry/two_view.h"

namespace arucoslam {

Rigid3 VehicleMotion(const Eigen::Vector3d& up, double angle_rad) {
  // Camera 2's orientation in camera 1 is a turn by angle about up; rotation maps camera 1
  // coordinates to camera 2's, so it is the inverse turn. The chord bisects the turn.
  const Eigen::AngleAxisd cam2_from_cam1(-angle_rad, up);
  const Eigen::Vector3d chord = Eigen::AngleAxisd(angle_rad / 2.0, up) * Eigen::Vector3d::UnitZ();
  const Eigen::Quaterniond rotation(cam2_from_cam1);
  return Rigid3(rotation, -(rotation * chord));
}

VehicleTwoViewResult SolveVehicleTwoView(const std::vector<Eigen::Vector2d>& x1,
                                         const std::vector<Eigen::Vector2d>& x2,
                                         const Eigen::Vector3d& up, double angle_centre_rad,
                                         double focal_px, const VehicleTwoViewOptions& options) {
  VehicleTwoViewResult best;
  best.cost = std::numeric_limits<double>::infinity();
  const std::size_t n = std::min(x1.size(), x2.size());
  const double max_error_sq = options.max_error_px * options.max_error_px;
  const double focal_sq = focal_px * focal_px;
  const int steps = static_cast<int>(std::ceil(options.angle_range_rad / options.angle_step_rad));
  for (int step = -steps; step <= steps; ++step) {
    const double angle = angle_centre_rad + step * options.angle_step_rad;
    const Rigid3 motion = VehicleMotion(up, angle);
    const Eigen::Matrix3d essential = EssentialOf(motion);
    double cost = 0.0;
    int inliers = 0;
    for (std::size_t i = 0; i < n && cost < best.cost; ++i) {
      const double error = SampsonErrorOfEssential(essential, x1[i], x2[i]);
      const double error_sq = error * error * focal_sq;
      cost += std::min(error_sq, max_error_sq);
      inliers += error_sq < max_error_sq ? 1 : 0;
    }
    if (cost < best.cost) {
      best.cost = cost;
      best.angle_rad = angle;
      best.cam2_from_cam1 = motion;
      best.num_inliers = inliers;
    }
  }
  return best;
}

double TwistAngle(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& axis) {
  double angle = 2.0 * std::atan2(rotation.vec().dot(axis), rotation.w());
  if (angle > M_PI) angle -= 2.0 * M_PI;
  if (angle <= -M_PI) angle += 2.0 * M_PI;
  return angle;
}

}  // namespace arucoslam
