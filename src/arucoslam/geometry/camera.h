// Camera models: pinhole with OpenCV's distortion family (radial-tangential k1 k2 p1 p2 k3,
// rational k4 k5 k6, thin prism s1..s4, tilted sensor tauX tauY) and equidistant fisheye
// (k1..k4), OpenCV's conventions, with analytic Jacobians.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace arucoslam {

// The values are stored in map files: append new models, never renumber.
enum class DistortionModel {
  kNone,
  kRadTan,       // k1 k2 p1 p2 k3 (OpenCV's 4 or 5 coefficients)
  kEquidistant,  // k1 k2 k3 k4 (OpenCV's fisheye module)
  kRational,     // k1 k2 p1 p2 k3 k4 k5 k6 (radial numerator k1..k3 over denominator k4..k6)
  kThinPrism,    // the rational eight + s1 s2 s3 s4
  kTilted,       // the thin-prism twelve + tauX tauY (sensor tilt in radians)
};

// Coefficients a model uses, in OpenCV's order: 0, 5, 4, 8, 12 or 14.
int NumDistortionCoefficients(DistortionModel model);
inline constexpr int kMaxDistortionCoefficients = 14;

// Intrinsics and distortion of one camera. Pixel centres are at integer coordinates
// (OpenCV). `distortion` holds the model's coefficients in OpenCV's order (k1 k2 p1 p2 k3 k4
// k5 k6 s1 s2 s3 s4 tauX tauY; equidistant k1 k2 k3 k4); entries the model does not use are 0.
struct CameraModel {
  int width = 0;
  int height = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  DistortionModel model = DistortionModel::kNone;
  std::array<double, kMaxDistortionCoefficients> distortion{};  // unused entries are zero
  double rate_hz = 0.0;                                         // frame rate where known, else 0

  // Positive size and focal lengths, finite values, zero beyond the model's coefficients.
  bool Check(std::string* why = nullptr) const;

  // The model's coefficients, as OpenCV's functions take them (empty for kNone; cv::fisheye
  // for kEquidistant, cv::projectPoints and cv::undistort for the others).
  std::vector<double> DistortionCoefficients() const;

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
