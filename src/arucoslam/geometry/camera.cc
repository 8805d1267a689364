#include "arucoslam/geometry/camera.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// Iteration limits of the inverse distortion (Newton, quadratic convergence): the error
// left after a step of size s is about s^2, so stopping once s < 1e-10 leaves ~1e-20.
constexpr int kMaxUndistortIterations = 20;
constexpr double kUndistortTolerance = 1e-10;  // step size (normalised units or radians)

// Below this radius (normalised units) the fisheye maps use their Taylor limits.
constexpr double kSmallRadius = 1e-8;
// Unprojection clamps the fisheye incidence angle just short of 90 degrees, where the
// normalised coordinates (tan theta) diverge.
constexpr double kMaxFisheyeTheta = 0.5 * std::numbers::pi - 1e-6;

using Matrix2d = Eigen::Matrix2d;

using Coefficients = std::array<double, kMaxDistortionCoefficients>;

// OpenCV's pinhole distortion before the sensor tilt, of normalised coordinates, and its 2x2
// Jacobian: radial (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6),
// tangential p1 p2, thin prism s1..s4. Coefficients a model lacks are zero, so this is the
// radial-tangential, rational and thin-prism models alike; kRadTanOnly leaves out the
// denominator and the prism terms (the radial-tangential model, which SLAM calls most).
template <bool kRadTanOnly>
Eigen::Vector2d DistortRational(const Coefficients& d, const Eigen::Vector2d& p,
                                Matrix2d* jacobian) {
  const double k1 = d[0], k2 = d[1], p1 = d[2], p2 = d[3], k3 = d[4];
  const double x = p.x(), y = p.y();
  const double r2 = x * x + y * y;
  double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  double radial_d_r2 = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2);
  Eigen::Vector2d prism = Eigen::Vector2d::Zero(), prism_d_r2 = Eigen::Vector2d::Zero();
  if constexpr (!kRadTanOnly) {
    const double k4 = d[5], k5 = d[6], k6 = d[7], s1 = d[8], s2 = d[9], s3 = d[10], s4 = d[11];
    const double denominator = 1.0 + r2 * (k4 + r2 * (k5 + r2 * k6));
    radial /= denominator;
    radial_d_r2 = (radial_d_r2 - radial * (k4 + r2 * (2.0 * k5 + 3.0 * k6 * r2))) / denominator;
    prism = r2 * Eigen::Vector2d(s1 + s2 * r2, s3 + s4 * r2);
    prism_d_r2 = Eigen::Vector2d(s1 + 2.0 * s2 * r2, s3 + 2.0 * s4 * r2);
  }
  const Eigen::Vector2d distorted(
      x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) + prism.x(),
      y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y + prism.y());
  if (jacobian != nullptr) {
    (*jacobian)(0, 0) =
        radial + 2.0 * x * (x * radial_d_r2 + prism_d_r2.x()) + 2.0 * p1 * y + 6.0 * p2 * x;
    (*jacobian)(0, 1) = 2.0 * y * (x * radial_d_r2 + prism_d_r2.x()) + 2.0 * p1 * x + 2.0 * p2 * y;
    (*jacobian)(1, 0) = 2.0 * x * (y * radial_d_r2 + prism_d_r2.y()) + 2.0 * p1 * x + 2.0 * p2 * y;
    (*jacobian)(1, 1) =
        radial + 2.0 * y * (y * radial_d_r2 + prism_d_r2.y()) + 6.0 * p1 * y + 2.0 * p2 * x;
  }
  return distorted;
}

// The homography of a sensor tilted by tau_x about x then tau_y about y (OpenCV's tilted
// model): R = Ry(tau_y) Rx(tau_x) re-projected onto the tilted plane along its normal,
// [[R22, 0, -R02], [0, R22, -R12], [0, 0, 1]] R.
Eigen::Matrix3d TiltHomography(double tau_x, double tau_y) {
  const double cx = std::cos(tau_x), sx = std::sin(tau_x);
  const double cy = std::cos(tau_y), sy = std::sin(tau_y);
  Eigen::Matrix3d rotation_x, rotation_y;
  rotation_x << 1.0, 0.0, 0.0, 0.0, cx, sx, 0.0, -sx, cx;
  rotation_y << cy, 0.0, -sy, 0.0, 1.0, 0.0, sy, 0.0, cy;
  const Eigen::Matrix3d rotation = rotation_y * rotation_x;
  Eigen::Matrix3d projection;
  projection << rotation(2, 2), 0.0, -rotation(0, 2), 0.0, rotation(2, 2), -rotation(1, 2), 0.0,
      0.0, 1.0;
  return projection * rotation;
}

// The homography applied to a point of the plane z = 1, and its 2x2 Jacobian.
Eigen::Vector2d ApplyHomography(const Eigen::Matrix3d& h, const Eigen::Vector2d& p,
                                Matrix2d* jacobian) {
  const Eigen::Vector3d mapped = h * p.homogeneous();
  const Eigen::Vector2d result = mapped.head<2>() / mapped.z();
  if (jacobian != nullptr) {
    *jacobian = (h.topLeftCorner<2, 2>() - result * h.block<1, 2>(2, 0)) / mapped.z();
  }
  return result;
}

// OpenCV's whole pinhole distortion: DistortRational, then the tilt for kTilted.
Eigen::Vector2d DistortOpenCv(const CameraModel& camera, const Eigen::Vector2d& p,
                              Matrix2d* jacobian) {
  if (camera.model == DistortionModel::kRadTan) {
    return DistortRational<true>(camera.distortion, p, jacobian);
  }
  const Eigen::Vector2d distorted = DistortRational<false>(camera.distortion, p, jacobian);
  if (camera.model != DistortionModel::kTilted) return distorted;
  Matrix2d tilt_jacobian;
  const Eigen::Vector2d tilted =
      ApplyHomography(TiltHomography(camera.distortion[12], camera.distortion[13]), distorted,
                      jacobian != nullptr ? &tilt_jacobian : nullptr);
  if (jacobian != nullptr) *jacobian = tilt_jacobian * *jacobian;
  return tilted;
}

// Newton on DistortRational(p) = distorted, started at the distorted point.
template <bool kRadTanOnly>
Eigen::Vector2d UndistortRational(const Coefficients& d, const Eigen::Vector2d& distorted) {
  Eigen::Vector2d p = distorted;
  for (int i = 0; i < kMaxUndistortIterations; ++i) {
    Matrix2d jacobian;
    const Eigen::Vector2d residual = DistortRational<kRadTanOnly>(d, p, &jacobian) - distorted;
    const double determinant = jacobian(0, 0) * jacobian(1, 1) - jacobian(0, 1) * jacobian(1, 0);
    const Eigen::Vector2d step(
        (jacobian(1, 1) * residual.x() - jacobian(0, 1) * residual.y()) / determinant,
        (jacobian(0, 0) * residual.y() - jacobian(1, 0) * residual.x()) / determinant);
    if (!step.allFinite()) break;
    p -= step;
    if (step.squaredNorm() < kUndistortTolerance * kUndistortTolerance) break;
  }
  return p;
}

// theta_d(theta) = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8) and its
// derivative, the equidistant (Kannala-Brandt) polynomial of OpenCV's fisheye module.
double FisheyeThetaD(const Coefficients& d, double theta, double* derivative) {
  const double t2 = theta * theta;
  const double poly = 1.0 + t2 * (d[0] + t2 * (d[1] + t2 * (d[2] + t2 * d[3])));
  if (derivative != nullptr) {
    *derivative = 1.0 + t2 * (3.0 * d[0] + t2 * (5.0 * d[1] + t2 * (7.0 * d[2] + 9.0 * t2 * d[3])));
  }
  return theta * poly;
}

// Equidistant distortion of normalised coordinates: p * theta_d / r, and its Jacobian.
Eigen::Vector2d DistortEquidistant(const Coefficients& d, const Eigen::Vector2d& p,
                                   Matrix2d* jacobian) {
  const double r = p.norm();
  if (r < kSmallRadius) {
    // scale(r) = 1 + (k1 - 1/3) r^2 + O(r^4): the Jacobian is the identity to O(r^2).
    if (jacobian != nullptr) jacobian->setIdentity();
    return p;
  }
  const double theta = std::atan(r);
  double theta_d_d_theta = 0.0;
  const double theta_d = FisheyeThetaD(d, theta, &theta_d_d_theta);
  const double scale = theta_d / r;
  if (jacobian != nullptr) {
    // d scale / d r = (theta_d'(theta) / (1 + r^2) - scale) / r; d r / d p = p^T / r.
    const double scale_d_r = (theta_d_d_theta / (1.0 + r * r) - scale) / r;
    *jacobian = scale * Matrix2d::Identity() + (scale_d_r / r) * p * p.transpose();
  }
  return scale * p;
}

}  // namespace

int NumDistortionCoefficients(DistortionModel model) {
  switch (model) {
    case DistortionModel::kNone:
      return 0;
    case DistortionModel::kRadTan:
      return 5;
    case DistortionModel::kEquidistant:
      return 4;
    case DistortionModel::kRational:
      return 8;
    case DistortionModel::kThinPrism:
      return 12;
    case DistortionModel::kTilted:
      return 14;
  }
  return 0;
}

bool CameraModel::Check(std::string* why) const {
  OptionCheck check(why);
  check.Above("width", width, 0);
  check.Above("height", height, 0);
  check.Rule(fx > 0.0 && std::isfinite(fx), "fx", fx, "finite and > 0");
  check.Rule(fy > 0.0 && std::isfinite(fy), "fy", fy, "finite and > 0");
  check.Rule(std::isfinite(cx), "cx", cx, "finite");
  check.Rule(std::isfinite(cy), "cy", cy, "finite");
  check.Rule(std::isfinite(rate_hz) && rate_hz >= 0.0, "rate_hz", rate_hz, "finite and >= 0");
  for (const double coefficient : distortion) {
    check.Rule(std::isfinite(coefficient), "distortion", coefficient, "finite");
  }
  const int used = NumDistortionCoefficients(model);
  for (int i = used; i < kMaxDistortionCoefficients; ++i) {
    check.Rule(distortion[i] == 0.0, "distortion", distortion[i],
               "0 beyond the model's coefficients");
  }
  // A tilt of 90 degrees or more folds the sensor plane onto itself.
  if (model == DistortionModel::kTilted) {
    constexpr double kMaxTilt = 0.5 * std::numbers::pi;
    check.Below("tilt tau_x", std::abs(distortion[12]), kMaxTilt, "pi/2 in magnitude");
    check.Below("tilt tau_y", std::abs(distortion[13]), kMaxTilt, "pi/2 in magnitude");
  }
  return check.ok();
}

std::vector<double> CameraModel::DistortionCoefficients() const {
  return std::vector<double>(distortion.begin(),
                             distortion.begin() + NumDistortionCoefficients(model));
}

Eigen::Vector2d CameraModel::Distort(const Eigen::Vector2d& normalised) const {
  Eigen::Vector2d distorted = normalised;
  switch (model) {
    case DistortionModel::kNone:
      break;
    case DistortionModel::kEquidistant:
      distorted = DistortEquidistant(distortion, normalised, nullptr);
      break;
    case DistortionModel::kRadTan:
    case DistortionModel::kRational:
    case DistortionModel::kThinPrism:
    case DistortionModel::kTilted:
      distorted = DistortOpenCv(*this, normalised, nullptr);
      break;
  }
  return Eigen::Vector2d(fx * distorted.x() + cx, fy * distorted.y() + cy);
}

std::optional<Eigen::Vector2d> CameraModel::Project(const Eigen::Vector3d& p_in_cam) const {
  if (!(p_in_cam.z() > 0.0)) return std::nullopt;
  return Distort(p_in_cam.head<2>() / p_in_cam.z());
}

Eigen::Vector2d CameraModel::Unproject(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d distorted((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  switch (model) {
    case DistortionModel::kNone:
      return distorted;
    case DistortionModel::kRadTan:
      return UndistortRational<true>(distortion, distorted);
    case DistortionModel::kRational:
    case DistortionModel::kThinPrism:
      return UndistortRational<false>(distortion, distorted);
    case DistortionModel::kTilted: {
      // The tilt is a homography: undone exactly before the iterative part.
      const Eigen::Matrix3d tilt = TiltHomography(distortion[12], distortion[13]);
      return UndistortRational<false>(distortion,
                                      ApplyHomography(tilt.inverse(), distorted, nullptr));
    }
    case DistortionModel::kEquidistant: {
      const double theta_d = distorted.norm();
      if (theta_d < kSmallRadius) return distorted;
      // Newton on theta_d(theta) = theta_d, started at theta = theta_d.
      double theta = std::min(theta_d, kMaxFisheyeTheta);
      for (int i = 0; i < kMaxUndistortIterations; ++i) {
        double derivative = 0.0;
        const double step = (FisheyeThetaD(distortion, theta, &derivative) - theta_d) / derivative;
        if (!std::isfinite(step)) break;
        theta = std::clamp(theta - step, 0.0, kMaxFisheyeTheta);
        if (std::abs(step) < kUndistortTolerance) break;
      }
      return distorted * (std::tan(theta) / theta_d);
    }
  }
  return distorted;
}

Eigen::Matrix<double, 2, 3> CameraModel::ProjectJacobian(const Eigen::Vector3d& p_in_cam) const {
  const double inverse_z = 1.0 / p_in_cam.z();
  const Eigen::Vector2d normalised = p_in_cam.head<2>() * inverse_z;
  // d normalised / d p_in_cam.
  Eigen::Matrix<double, 2, 3> normalised_d_point;
  normalised_d_point << inverse_z, 0.0, -normalised.x() * inverse_z,  //
      0.0, inverse_z, -normalised.y() * inverse_z;
  Matrix2d distorted_d_normalised = Matrix2d::Identity();
  switch (model) {
    case DistortionModel::kNone:
      break;
    case DistortionModel::kEquidistant:
      DistortEquidistant(distortion, normalised, &distorted_d_normalised);
      break;
    case DistortionModel::kRadTan:
    case DistortionModel::kRational:
    case DistortionModel::kThinPrism:
    case DistortionModel::kTilted:
      DistortOpenCv(*this, normalised, &distorted_d_normalised);
      break;
  }
  const Eigen::DiagonalMatrix<double, 2> pixel_d_distorted(fx, fy);
  return pixel_d_distorted * distorted_d_normalised * normalised_d_point;
}

CameraModel PinholeCamera(int width, int height, double focal_px) {
  CameraModel camera;
  camera.width = width;
  camera.height = height;
  camera.fx = camera.fy = focal_px;
  camera.cx = 0.5 * (width - 1);
  camera.cy = 0.5 * (height - 1);
  return camera;
}

std::string DistortionModelName(DistortionModel model) {
  switch (model) {
    case DistortionModel::kNone:
      return "none";
    case DistortionModel::kRadTan:
      return "radtan";
    case DistortionModel::kEquidistant:
      return "equidistant";
    case DistortionModel::kRational:
      return "rational";
    case DistortionModel::kThinPrism:
      return "thin-prism";
    case DistortionModel::kTilted:
      return "tilted";
  }
  return "unknown";
}

}  // namespace arucoslam
