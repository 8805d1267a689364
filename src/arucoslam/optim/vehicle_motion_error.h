// Soft priors of a forward-looking camera on a wheeled vehicle: it moves along its viewing
// direction (no sideways slip: LateralVelocityError) at a speed that changes only as fast as
// bounded acceleration allows (ForwardSpeedChangeError). Turns are free: vision sees them.
#pragma once

#include <Eigen/Core>

#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

// The vehicle model. Lateral: the camera's sideways speed (along its x axis, mean of both
// ends of an interval) has standard deviation lateral_speed_sigma_mps (slip, mounting yaw,
// path deviation). Forward: the speed along the optical axis drifts as white-noise
// acceleration of power spectral density forward_acceleration_psd (m^2/s^3): by sqrt(q t) in
// t seconds; 0.1 lets a 1 m/s vehicle speed up or slow down by about 0.3 m/s in a second.
// Poses farther apart in time than max_gap_s are not linked.
struct VehicleMotionPriorOptions {
  double lateral_speed_sigma_mps = 0.05;
  double forward_acceleration_psd = 0.1;
  double max_gap_s = 2.0;

  bool Check() const {
    return lateral_speed_sigma_mps > 0.0 && forward_acceleration_psd > 0.0 && max_gap_s > 0.0;
  }
};

using VehicleMotionPoseJacobian = Eigen::Matrix<double, 1, 6>;

// Whitened r = x^T (R0 d + R1 d) / (2 dt sigma_lat) for the poses cam_from_world = (Ri, ti)
// of two frames dt seconds apart, d = c1 - c0 their camera centres: the mean sideways speed
// seen from both ends (zero on a straight line and on a circular arc driven forwards).
// Jacobians (pointers may be null) w.r.t. the left perturbation of each cam_from_world
// ([upsilon; omega] as in Rigid3::Exp).
class LateralVelocityError {
 public:
  LateralVelocityError(const VehicleMotionPriorOptions& options, double dt);

  void Evaluate(const Rigid3& cam0_from_world, const Rigid3& cam1_from_world, double* residual,
                VehicleMotionPoseJacobian* d_pose0 = nullptr,
                VehicleMotionPoseJacobian* d_pose1 = nullptr) const;

 private:
  double weight_;
};

// Whitened r = (s2 - s1) / sqrt(q (dt1 + dt2) / 3) over three poses in time order, dt1 and dt2
// seconds apart, si = z^T (Ra d + Rb d) / (2 dt) the forward speed of interval i seen from
// both its ends. Jacobians as LateralVelocityError's.
class ForwardSpeedChangeError {
 public:
  ForwardSpeedChangeError(const VehicleMotionPriorOptions& options, double dt1, double dt2);

  void Evaluate(const Rigid3& cam0_from_world, const Rigid3& cam1_from_world,
                const Rigid3& cam2_from_world, double* residual,
                VehicleMotionPoseJacobian* d_pose0 = nullptr,
                VehicleMotionPoseJacobian* d_pose1 = nullptr,
                VehicleMotionPoseJacobian* d_pose2 = nullptr) const;

 private:
  double weight1_, weight2_;  // whitened coefficients of the two intervals' z^T u
};

}  // namespace arucoslam
