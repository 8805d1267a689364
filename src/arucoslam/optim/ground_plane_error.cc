#include "arucoslam/optim/ground_plane_error.h"

namespace arucoslam {

GroundPlane MeanGroundPlane(const std::vector<Rigid3>& cams_from_world) {
  GroundPlane plane;
  if (cams_from_world.empty()) return plane;
  for (const Rigid3& cam_from_world : cams_from_world) {
    const Rigid3 world_from_cam = cam_from_world.Inverse();
    plane.height_m += world_from_cam.translation.z();
    plane.up_in_camera += cam_from_world.rotation * Eigen::Vector3d::UnitZ();
  }
  plane.height_m /= static_cast<double>(cams_from_world.size());
  plane.up_in_camera.normalize();
  return plane;
}

// With cam_from_world = (R, t) perturbed to Exp(delta) (R, t), to first order the centre
// c = -R^T t moves by -R^T upsilon and the up direction R^T u by R^T [u]x omega.
void GroundPlaneError::Evaluate(const Rigid3& cam_from_world, const GroundPlane& plane,
                                Eigen::Vector3d* residual, GroundPlanePoseJacobian* d_pose,
                                GroundPlaneHeightJacobian* d_height,
                                GroundPlaneUpJacobian* d_up) const {
  const Eigen::Matrix3d world_from_cam = cam_from_world.rotation.toRotationMatrix().transpose();
  const Eigen::Vector3d centre = -(world_from_cam * cam_from_world.translation);
  const Eigen::Vector3d up_in_world = world_from_cam * plane.up_in_camera;
  *residual << inverse_height_sigma_ * (centre.z() - plane.height_m),
      inverse_tilt_sigma_ * up_in_world.x(), inverse_tilt_sigma_ * up_in_world.y();
  if (d_pose != nullptr) {
    d_pose->setZero();
    d_pose->block<1, 3>(0, 0) = -inverse_height_sigma_ * world_from_cam.row(2);
    d_pose->block<2, 3>(1, 3) =
        inverse_tilt_sigma_ * (world_from_cam * Hat(plane.up_in_camera)).topRows<2>();
  }
  if (d_height != nullptr) *d_height << -inverse_height_sigma_, 0.0, 0.0;
  if (d_up != nullptr) {
    d_up->setZero();
    d_up->bottomRows<2>() = inverse_tilt_sigma_ * world_from_cam.topRows<2>();
  }
}

}  // namespace arucoslam
