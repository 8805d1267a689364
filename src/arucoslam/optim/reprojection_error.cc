#include "arucoslam/optim/reprojection_error.h"

namespace arucoslam {

bool ReprojectionError::Evaluate(const Rigid3& cam_from_world, const Eigen::Vector3d& p_in_world,
                                 Eigen::Vector2d* residual, PoseJacobian* d_pose,
                                 PointJacobian* d_point) const {
  return Evaluate(cam_from_world.RotationMatrix(), cam_from_world.translation, p_in_world, residual,
                  d_pose, d_point);
}

bool ReprojectionError::Evaluate(const Eigen::Matrix3d& rotation,
                                 const Eigen::Vector3d& translation,
                                 const Eigen::Vector3d& p_in_world, Eigen::Vector2d* residual,
                                 PoseJacobian* d_pose, PointJacobian* d_point) const {
  const Eigen::Vector3d p_in_cam = rotation * p_in_world + translation;
  const double z = p_in_cam.z();
  if (!(z > kMinDepth)) return false;
  const double inv_z = 1.0 / z;
  const double u = intrinsics_.fx * p_in_cam.x() * inv_z + intrinsics_.cx;
  const double v = intrinsics_.fy * p_in_cam.y() * inv_z + intrinsics_.cy;
  if (residual != nullptr) *residual = Eigen::Vector2d(u, v) - observed_;
  if (d_pose == nullptr && d_point == nullptr) return true;

  // d pixel / d p_in_cam.
  Eigen::Matrix<double, 2, 3> d_projection;
  d_projection << intrinsics_.fx * inv_z, 0.0, -intrinsics_.fx * p_in_cam.x() * inv_z * inv_z, 0.0,
      intrinsics_.fy * inv_z, -intrinsics_.fy * p_in_cam.y() * inv_z * inv_z;
  if (d_pose != nullptr) {
    // Exp(delta) * p_in_cam = p_in_cam + upsilon + omega x p_in_cam to first order.
    d_pose->leftCols<3>() = d_projection;
    d_pose->rightCols<3>() = -d_projection * Hat(p_in_cam);
  }
  if (d_point != nullptr) *d_point = d_projection * rotation;
  return true;
}

}  // namespace arucoslam
