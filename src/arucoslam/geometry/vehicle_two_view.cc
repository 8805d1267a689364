#include "arucoslam/geometry/vehicle_two_view.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

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
    const Eigen::Vector3d& t = motion.translation;
    Eigen::Matrix3d t_cross;
    t_cross << 0.0, -t.z(), t.y(), t.z(), 0.0, -t.x(), -t.y(), t.x(), 0.0;
    const Eigen::Matrix3d essential = t_cross * motion.rotation.toRotationMatrix();
    double cost = 0.0;
    int inliers = 0;
    for (std::size_t i = 0; i < n && cost < best.cost; ++i) {
      const Eigen::Vector3d p1 = x1[i].homogeneous(), p2 = x2[i].homogeneous();
      const Eigen::Vector3d line2 = essential * p1, line1 = essential.transpose() * p2;
      const double numerator = p2.dot(line2);
      const double denominator = line2.head<2>().squaredNorm() + line1.head<2>().squaredNorm();
      const double error_sq =
          denominator > 0.0 ? numerator * numerator / denominator * focal_sq : max_error_sq;
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
