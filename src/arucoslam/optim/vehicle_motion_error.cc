#include "arucoslam/optim/vehicle_motion_error.h"

#include <Eigen/Geometry>
#include <cmath>

namespace arucoslam {
namespace {

using Matrix36d = Eigen::Matrix<double, 3, 6>;

// u = R0 d + R1 d, the displacement d = c1 - c0 in both cameras' frames, and its Jacobians
// w.r.t. the left perturbations of both poses. With (R, t) -> Exp(delta) (R, t) the centre
// moves by -R^T upsilon and R v by -[R v]x omega (to first order).
struct Interval {
  Eigen::Vector3d u;
  Matrix36d d_pose0, d_pose1;
};

Interval MakeInterval(const Rigid3& cam0_from_world, const Rigid3& cam1_from_world) {
  const Eigen::Matrix3d r0 = cam0_from_world.rotation.toRotationMatrix();
  const Eigen::Matrix3d r1 = cam1_from_world.rotation.toRotationMatrix();
  const Eigen::Vector3d d =
      cam1_from_world.Inverse().translation - cam0_from_world.Inverse().translation;
  const Eigen::Vector3d a = r0 * d, b = r1 * d;
  Interval interval;
  interval.u = a + b;
  const Eigen::Matrix3d sum = r0 + r1;
  interval.d_pose0.leftCols<3>() = sum * r0.transpose();
  interval.d_pose0.rightCols<3>() = -Hat(a);
  interval.d_pose1.leftCols<3>() = -sum * r1.transpose();
  interval.d_pose1.rightCols<3>() = -Hat(b);
  return interval;
}

}  // namespace

LateralVelocityError::LateralVelocityError(const VehicleMotionPriorOptions& options, double dt)
    : weight_(1.0 / (2.0 * dt * options.lateral_speed_sigma_mps)) {}

void LateralVelocityError::Evaluate(const Rigid3& cam0_from_world, const Rigid3& cam1_from_world,
                                    double* residual, VehicleMotionPoseJacobian* d_pose0,
                                    VehicleMotionPoseJacobian* d_pose1) const {
  const Interval interval = MakeInterval(cam0_from_world, cam1_from_world);
  *residual = weight_ * interval.u.x();
  if (d_pose0 != nullptr) *d_pose0 = weight_ * interval.d_pose0.row(0);
  if (d_pose1 != nullptr) *d_pose1 = weight_ * interval.d_pose1.row(0);
}

ForwardSpeedChangeError::ForwardSpeedChangeError(const VehicleMotionPriorOptions& options,
                                                 double dt1, double dt2) {
  const double inverse_sigma =
      1.0 / std::sqrt(options.forward_acceleration_psd * (dt1 + dt2) / 3.0);
  weight1_ = -inverse_sigma / (2.0 * dt1);
  weight2_ = inverse_sigma / (2.0 * dt2);
}

void ForwardSpeedChangeError::Evaluate(const Rigid3& cam0_from_world, const Rigid3& cam1_from_world,
                                       const Rigid3& cam2_from_world, double* residual,
                                       VehicleMotionPoseJacobian* d_pose0,
                                       VehicleMotionPoseJacobian* d_pose1,
                                       VehicleMotionPoseJacobian* d_pose2) const {
  const Interval first = MakeInterval(cam0_from_world, cam1_from_world);
  const Interval second = MakeInterval(cam1_from_world, cam2_from_world);
  *residual = weight1_ * first.u.z() + weight2_ * second.u.z();
  if (d_pose0 != nullptr) *d_pose0 = weight1_ * first.d_pose0.row(2);
  if (d_pose1 != nullptr) {
    *d_pose1 = weight1_ * first.d_pose1.row(2) + weight2_ * second.d_pose0.row(2);
  }
  if (d_pose2 != nullptr) *d_pose2 = weight2_ * second.d_pose1.row(2);
}

}  // namespace arucoslam
