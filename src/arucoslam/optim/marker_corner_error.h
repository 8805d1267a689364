// MarkerCornerError: the 8-vector of corner pixel errors of one marker seen by one camera,
// with analytic Jacobians w.r.t. left SE(3) perturbations of cam_from_world and world_from_marker.
#pragma once

#include <Eigen/Core>
#include <array>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/optim/reprojection_error.h"

namespace arucoslam {

using Vector8d = Eigen::Matrix<double, 8, 1>;
// Rows: corner 0 (u, v), corner 1 (u, v), ...; columns: [upsilon; omega] of a left
// perturbation, pose <- Exp(delta) * pose, as PoseJacobian.
using MarkerCornerJacobian = Eigen::Matrix<double, 8, 6>;

// Undistorted pixels (pinhole K of `camera` applied to CameraModel::Unproject) of detected
// corners: what the residuals here and every optimisation compare against.
std::array<Eigen::Vector2d, 4> UndistortedCorners(const CameraModel& camera,
                                                  const std::array<Eigen::Vector2d, 4>& corners_px);

// r = [K * project(cam_from_world * world_from_marker * x_i) - observed_i], i = 0..3, pixels.
class MarkerCornerError {
 public:
  // `corners_in_marker`: the marker's corners in its frame (MarkerInfo::CornersInMarker);
  // `observed`: their undistorted pixels, same order.
  MarkerCornerError(const PinholeIntrinsics& intrinsics,
                    const std::array<Eigen::Vector3d, 4>& corners_in_marker,
                    const std::array<Eigen::Vector2d, 4>& observed);

  // False (outputs untouched) when a corner is not in front of the camera. Jacobian
  // pointers may be null; d_marker is the Jacobian w.r.t. world_from_marker.
  bool Evaluate(const Rigid3& cam_from_world, const Rigid3& world_from_marker, Vector8d* residual,
                MarkerCornerJacobian* d_cam = nullptr,
                MarkerCornerJacobian* d_marker = nullptr) const;

  const std::array<Eigen::Vector2d, 4>& observed() const { return observed_; }

 private:
  PinholeIntrinsics intrinsics_;
  std::array<Eigen::Vector3d, 4> corners_in_marker_;
  std::array<Eigen::Vector2d, 4> observed_;
};

}  // namespace arucoslam
