#include "arucoslam/optim/smooth_motion_error.h"

#include <cmath>

namespace arucoslam {
namespace {

// With cam_from_world = (R, t) perturbed to Exp(delta) (R, t), to first order the centre
// c = -R^T t moves by -R^T upsilon and not at all with omega.
void CentreJacobian(const Rigid3& cam_from_world, double weight, SmoothMotionPoseJacobian* d) {
  if (d == nullptr) return;
  d->setZero();
  d->leftCols<3>() = -weight * cam_from_world.rotation.toRotationMatrix().transpose();
}

Eigen::Vector3d Centre(const Rigid3& cam_from_world) {
  return -(cam_from_world.rotation.conjugate() * cam_from_world.translation);
}

}  // namespace

SmoothMotionError::SmoothMotionError(const SmoothMotionPriorOptions& options, double dt1,
                                     double dt2) {
  const double inverse_sigma = 1.0 / std::sqrt(options.acceleration_psd * (dt1 + dt2) / 3.0);
  weight0_ = inverse_sigma / dt1;
  weight2_ = inverse_sigma / dt2;
  weight1_ = -(weight0_ + weight2_);
}

void SmoothMotionError::Evaluate(const Rigid3& cam0_from_world, const Rigid3& cam1_from_world,
                                 const Rigid3& cam2_from_world, Eigen::Vector3d* residual,
                                 SmoothMotionPoseJacobian* d_pose0,
                                 SmoothMotionPoseJacobian* d_pose1,
                                 SmoothMotionPoseJacobian* d_pose2) const {
  *residual = weight0_ * Centre(cam0_from_world) + weight1_ * Centre(cam1_from_world) +
              weight2_ * Centre(cam2_from_world);
  CentreJacobian(cam0_from_world, weight0_, d_pose0);
  CentreJacobian(cam1_from_world, weight1_, d_pose1);
  CentreJacobian(cam2_from_world, weight2_, d_pose2);
}

}  // namespace arucoslam
