// ReprojectionError: the residual of one keypoint observation of one 3D point, with analytic
// Jacobians w.r.t. a left SE(3) perturbation of cam_from_world and w.r.t. the point.
#pragma once

#include <Eigen/Core>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

// Pinhole intrinsics in pixels. Optimisation works on *undistorted* pixel coordinates:
// keypoints are undistorted once at extraction (CameraModel::Unproject, then K), so the
// residuals here are pure pinhole and the robust thresholds stay in pixels.
struct PinholeIntrinsics {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;

  static PinholeIntrinsics FromCamera(const CameraModel& camera) {
    return {camera.fx, camera.fy, camera.cx, camera.cy};
  }
  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Above("fx", fx, 0.0);
    check.Above("fy", fy, 0.0);
    return check.ok();
  }
  // Normalised undistorted coordinates (x/z, y/z) -> undistorted pixel.
  Eigen::Vector2d ToPixel(const Eigen::Vector2d& normalised) const {
    return {fx * normalised.x() + cx, fy * normalised.y() + cy};
  }
};

// Jacobian shapes. The pose tangent is [upsilon; omega] as in Rigid3::Exp, applied on the
// left: cam_from_world <- Exp(delta) * cam_from_world.
using PoseJacobian = Eigen::Matrix<double, 2, 6>;
using PointJacobian = Eigen::Matrix<double, 2, 3>;

// Residual r = K * (p_in_cam / z) - observed, in pixels, p_in_cam = cam_from_world * p.
class ReprojectionError {
 public:
  // Points closer than this depth (metres) in front of the camera are rejected.
  static constexpr double kMinDepth = 1e-6;

  ReprojectionError(const PinholeIntrinsics& intrinsics, const Eigen::Vector2d& observed)
      : intrinsics_(intrinsics), observed_(observed) {}

  // Returns false (and leaves the outputs untouched) when the point is not in front of
  // the camera. Jacobian pointers may be null.
  bool Evaluate(const Rigid3& cam_from_world, const Eigen::Vector3d& p_in_world,
                Eigen::Vector2d* residual, PoseJacobian* d_pose = nullptr,
                PointJacobian* d_point = nullptr) const;

  // Same with the pose as a rotation matrix + translation (what the solvers hold).
  bool Evaluate(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation,
                const Eigen::Vector3d& p_in_world, Eigen::Vector2d* residual, PoseJacobian* d_pose,
                PointJacobian* d_point) const;

  const Eigen::Vector2d& observed() const { return observed_; }

 private:
  PinholeIntrinsics intrinsics_;
  Eigen::Vector2d observed_;
};

// Chi-square threshold of a 2D residual at 95% (2 degrees of freedom), applied to
// |r|^2 / sigma^2 as ORB-SLAM does; sigma is the keypoint's pixel noise (octave scale).
inline constexpr double kChiSquare2Dof95 = 5.991;

}  // namespace arucoslam
