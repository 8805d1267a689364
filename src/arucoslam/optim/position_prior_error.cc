#include "arucoslam/optim/position_prior_error.h"

namespace arucoslam {

// With cam_from_world = (R, t) perturbed to Exp(delta) (R, t), to first order the centre
// moves by -R^T upsilon and not at all with omega (the rotation turns about the centre).
void PositionPriorError::Evaluate(const Rigid3& cam_from_world, Eigen::Vector3d* residual,
                                  PositionPriorPoseJacobian* d_pose) const {
  const Eigen::Matrix3d world_from_cam = cam_from_world.rotation.toRotationMatrix().transpose();
  const Eigen::Vector3d centre = -(world_from_cam * cam_from_world.translation);
  *residual = inverse_sigma_ * (centre - centre_in_world_);
  if (d_pose != nullptr) {
    d_pose->setZero();
    d_pose->leftCols<3>() = -inverse_sigma_ * world_from_cam;
  }
}

}  // namespace arucoslam
