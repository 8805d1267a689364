// Camera models: pinhole with radial-tangential distortion (k1 k2 p1 p2 k3) and
// equidistant fisheye (k1..k4), OpenCV's conventions, with analytic Jacobians.
#pragma once

#include <Eigen/Core>

#include <array>
#include <optional>
#include <string>

namespace arucoslam {

enum class DistortionModel { kNone, kRadTan, kEquidistant };

// Intrinsics and distortion of one camera. Pixel centres are at integer coordinates
// (OpenCV). For kRadTan `distortion` holds k1 k2 p1 p2 k3; for kEquidistant k1 k2 k3 k4 (0).
struct CameraModel {
  int width = 0;
  int height = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  DistortionModel model = DistortionModel::kNone;
  std::array<double, 5> distortion{};  // unused entries are zero
  double rate_hz = 0.0;                 // frame rate where known, else 0

  bool Check() const;  // positive size and focal lengths, finite values

  // Point in the camera frame (z forward) -> pixel. nullopt when z <= 0.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& p_in_cam) const;
  // Pixel -> normalised image coordinates (x/z, y/z) with distortion removed (Newton).
  // Fisheye pixels whose ray is 90 degrees or more off axis are clamped just short of 90.
  Eigen::Vector2d Unproject(const Eigen::Vector2d& pixel) const;
  // Normalised undistorted coordinates -> pixel.
  Eigen::Vector2d Distort(const Eigen::Vector2d& normalised) const;
  // d pixel / d p_in_cam (2x3), for z > 0.
  Eigen::Matrix<double, 2, 3> ProjectJacobian(const Eigen::Vector3d& p_in_cam) const;

  bool InImage(const Eigen::Vector2d& pixel, double border = 0.0) const {
    return pixel.x() >= border && pixel.y() >= border && pixel.x() <= width - 1 - border &&
           pixel.y() <= height - 1 - border;
  }
};

std::string DistortionModelName(DistortionModel model);

// A distortion-free camera of `width` x `height` pixels with focal length `focal_px` (fx = fy)
// and the principal point at the image centre ((width - 1) / 2, (height - 1) / 2).
CameraModel PinholeCamera(int width, int height, double focal_px);

}  // namespace arucoslam
