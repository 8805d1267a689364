// SmoothMotionError: the soft prior that a vehicle's camera moves smoothly: over three poses in
// time order, the mean velocities of the two intervals differ only as much as bounded
// acceleration allows (a white-noise-acceleration model on the camera centre).
#pragma once

#include <Eigen/Core>

#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

// How quickly a vehicle's velocity changes: the power spectral density q (m^2/s^3) of its
// acceleration, taken as white noise, so that the velocity drifts by sqrt(q t) in t seconds.
// The default, 0.1, lets a 1 m/s vehicle speed up or slow down by about 0.3 m/s in a second,
// or turn a corner at walking pace. Poses farther apart in time than max_gap_s are not linked.
struct SmoothMotionPriorOptions {
  double acceleration_psd = 0.1;
  double max_gap_s = 2.0;

  bool Check() const { return acceleration_psd > 0.0 && max_gap_s > 0.0; }
};

using SmoothMotionPoseJacobian = Eigen::Matrix<double, 3, 6>;

// Whitened residual r = ((c2 - c1) / dt2 - (c1 - c0) / dt1) / sqrt(q (dt1 + dt2) / 3) for the
// camera centres c0, c1, c2 of three poses dt1 and dt2 seconds apart: the difference of the two
// mean velocities, whose variance under white-noise acceleration is q (dt1 + dt2) / 3.
// Jacobians (pointers may be null) w.r.t. the left perturbation of each cam_from_world
// ([upsilon; omega] as in Rigid3::Exp).
class SmoothMotionError {
 public:
  SmoothMotionError(const SmoothMotionPriorOptions& options, double dt1, double dt2);

  void Evaluate(const Rigid3& cam0_from_world, const Rigid3& cam1_from_world,
                const Rigid3& cam2_from_world, Eigen::Vector3d* residual,
                SmoothMotionPoseJacobian* d_pose0 = nullptr,
                SmoothMotionPoseJacobian* d_pose1 = nullptr,
                SmoothMotionPoseJacobian* d_pose2 = nullptr) const;

 private:
  double weight0_, weight1_, weight2_;  // whitened coefficients of c0, c1, c2
};

}  // namespace arucoslam
