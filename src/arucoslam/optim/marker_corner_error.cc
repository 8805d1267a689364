#include "arucoslam/optim/marker_corner_error.h"

namespace arucoslam {

std::array<Eigen::Vector2d, 4> UndistortedCorners(
    const CameraModel& camera, const std::array<Eigen::Vector2d, 4>& corners_px) {
  const PinholeIntrinsics intrinsics = PinholeIntrinsics::FromCamera(camera);
  std::array<Eigen::Vector2d, 4> undistorted;
  for (int i = 0; i < 4; ++i) undistorted[i] = intrinsics.ToPixel(camera.Unproject(corners_px[i]));
  return undistorted;
}

MarkerCornerError::MarkerCornerError(const PinholeIntrinsics& intrinsics,
                                     const std::array<Eigen::Vector3d, 4>& corners_in_marker,
                                     const std::array<Eigen::Vector2d, 4>& observed)
    : intrinsics_(intrinsics), corners_in_marker_(corners_in_marker), observed_(observed) {}

bool MarkerCornerError::Evaluate(const Rigid3& cam_from_world, const Rigid3& world_from_marker,
                                 Vector8d* residual, MarkerCornerJacobian* d_cam,
                                 MarkerCornerJacobian* d_marker) const {
  const Eigen::Matrix3d rotation = cam_from_world.RotationMatrix();
  Vector8d r;
  MarkerCornerJacobian jc, jm;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d p_in_world = world_from_marker * corners_in_marker_[i];
    Eigen::Vector2d corner_residual;
    PoseJacobian d_pose;
    PointJacobian d_point;
    const bool jacobians = d_cam != nullptr || d_marker != nullptr;
    if (!ReprojectionError(intrinsics_, observed_[i])
             .Evaluate(rotation, cam_from_world.translation, p_in_world, &corner_residual,
                       jacobians ? &d_pose : nullptr, jacobians ? &d_point : nullptr)) {
      return false;
    }
    r.segment<2>(2 * i) = corner_residual;
    if (!jacobians) continue;
    jc.block<2, 6>(2 * i, 0) = d_pose;
    // Exp(delta) * world_from_marker moves the corner by upsilon + omega x p_in_world.
    jm.block<2, 3>(2 * i, 0) = d_point;
    jm.block<2, 3>(2 * i, 3) = -d_point * Hat(p_in_world);
  }
  if (residual != nullptr) *residual = r;
  if (d_cam != nullptr) *d_cam = jc;
  if (d_marker != nullptr) *d_marker = jm;
  return true;
}

}  // namespace arucoslam
