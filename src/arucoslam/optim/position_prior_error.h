// PositionPriorError: a soft prior on where a camera is in the world (its centre), such as
// the bridge over a tracking gap predicts for the first keyframe after it.
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

// The centre of problem pose `pose_index` should be `centre_in_world`, give or take
// `sigma_m` along each world axis.
struct PositionPrior {
  std::size_t pose_index = 0;
  Eigen::Vector3d centre_in_world = Eigen::Vector3d::Zero();
  double sigma_m = 1.0;
};

using PositionPriorPoseJacobian = Eigen::Matrix<double, 3, 6>;

// Whitened residual r = (c - centre_in_world) / sigma_m for a camera with centre
// c = -R^T t (cam_from_world = (R, t)). Jacobian (may be null) w.r.t. the left perturbation
// of cam_from_world ([upsilon; omega] as in Rigid3::Exp).
class PositionPriorError {
 public:
  explicit PositionPriorError(const PositionPrior& prior)
      : centre_in_world_(prior.centre_in_world), inverse_sigma_(1.0 / prior.sigma_m) {}

  void Evaluate(const Rigid3& cam_from_world, Eigen::Vector3d* residual,
                PositionPriorPoseJacobian* d_pose = nullptr) const;

 private:
  Eigen::Vector3d centre_in_world_;
  double inverse_sigma_;
};

}  // namespace arucoslam
