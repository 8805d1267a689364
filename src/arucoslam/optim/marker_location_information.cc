#include "arucoslam/optim/marker_location_information.h"

#include "arucoslam/markers/marker_pose.h"
#include "arucoslam/optim/marker_corner_error.h"

namespace arucoslam {

Matrix6d MarkerLocationInformation(const Rigid3& world_from_cam,
                                   const std::vector<MarkerPoseObservation>& markers,
                                   const PinholeIntrinsics& intrinsics) {
  const Rigid3 cam_from_world = world_from_cam.Inverse();
  // MarkerCornerError's Jacobian is w.r.t. cam_from_world <- Exp([u; w]) * cam_from_world,
  // which moves the centre by -R_world_from_cam * u and the camera-frame rotation by -w.
  Matrix6d to_left = Matrix6d::Zero();
  to_left.topLeftCorner<3, 3>() = -cam_from_world.RotationMatrix();
  to_left.bottomRightCorner<3, 3>() = -Eigen::Matrix3d::Identity();
  Matrix6d information = Matrix6d::Zero();
  for (const MarkerPoseObservation& marker : markers) {
    const MarkerCornerError error(intrinsics, SquareCorners(marker.size), marker.corners_px);
    MarkerCornerJacobian d_cam;
    if (!error.Evaluate(cam_from_world, marker.world_from_marker, nullptr, &d_cam)) continue;
    const MarkerCornerJacobian d_error = d_cam * to_left;
    information += d_error.transpose() * d_error / (marker.sigma_px * marker.sigma_px);
  }
  return information;
}

}  // namespace arucoslam
