#include "arucoslam/geometry/sim3.h"

#include <cmath>

namespace arucoslam {
namespace {

constexpr double kEpsilon = 1e-8;
// Where both |sigma| and theta are below this, W's coefficients come from their Taylor
// series (the closed forms cancel catastrophically near the origin).
constexpr double kSeriesRadius = 1e-2;
constexpr int kSeriesTerms = 9;  // powers of sigma; |sigma|^9 / 9! < 1e-23

// The matrix W with t = W * upsilon in exp(upsilon, omega, sigma):
//   W = integral_0^1 e^(sigma s) exp(s omega^) ds = c I + a omega^ + b omega^2, with
//   c = int e^(sigma s), a = int e^(sigma s) sin(theta s) / theta,
//   b = int e^(sigma s) (1 - cos(theta s)) / theta^2 (Strasdat's thesis, A.5).
Eigen::Matrix3d SimilarityV(const Eigen::Vector3d& omega, double sigma) {
  const double theta = omega.norm();
  const double theta2 = theta * theta;
  const Eigen::Matrix3d omega_hat = Hat(omega);
  double a = 0.0, b = 0.0, c = 0.0;
  if (std::abs(sigma) < kSeriesRadius && theta < kSeriesRadius) {
    // Expand e^(sigma s) = sum sigma^n s^n / n! and the trigonometric factors to theta^4.
    const double theta4 = theta2 * theta2;
    double sigma_power_over_factorial = 1.0;  // sigma^n / n!
    for (int n = 0; n < kSeriesTerms; ++n) {
      const double k = n;
      c += sigma_power_over_factorial / (k + 1.0);
      a += sigma_power_over_factorial *
           (1.0 / (k + 2.0) - theta2 / (6.0 * (k + 4.0)) + theta4 / (120.0 * (k + 6.0)));
      b += sigma_power_over_factorial *
           (1.0 / (2.0 * (k + 3.0)) - theta2 / (24.0 * (k + 5.0)) + theta4 / (720.0 * (k + 7.0)));
      sigma_power_over_factorial *= sigma / (k + 1.0);
    }
  } else {
    const double scale = std::exp(sigma);
    c = std::abs(sigma) < kEpsilon ? 1.0 + 0.5 * sigma : std::expm1(sigma) / sigma;
    if (theta < kEpsilon) {
      // theta -> 0 limits; here |sigma| >= kSeriesRadius.
      const double sigma2 = sigma * sigma;
      a = ((sigma - 1.0) * scale + 1.0) / sigma2;
      b = (scale * (0.5 * sigma2 - sigma + 1.0) - 1.0) / (sigma2 * sigma);
    } else {
      const double sin_theta = std::sin(theta);
      const double cos_theta = std::cos(theta);
      const double denominator = sigma * sigma + theta2;
      a = (scale * (sigma * sin_theta - theta * cos_theta) + theta) / (theta * denominator);
      b = (c - (scale * (sigma * cos_theta + theta * sin_theta) - sigma) / denominator) / theta2;
    }
  }
  return c * Eigen::Matrix3d::Identity() + a * omega_hat + b * omega_hat * omega_hat;
}

}  // namespace

Eigen::Matrix4d Sim3::ToMatrix() const {
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
  matrix.topLeftCorner<3, 3>() = scale * rotation.toRotationMatrix();
  matrix.topRightCorner<3, 1>() = translation;
  return matrix;
}

Sim3 Sim3::Inverse() const {
  const Eigen::Quaterniond inverse_rotation = rotation.conjugate();
  const double inverse_scale = 1.0 / scale;
  return Sim3(inverse_scale, inverse_rotation, -inverse_scale * (inverse_rotation * translation));
}

Sim3 Sim3::Exp(const Vector7d& tangent) {
  const Eigen::Vector3d upsilon = tangent.head<3>();
  const Eigen::Vector3d omega = tangent.segment<3>(3);
  const double sigma = tangent(6);
  return Sim3(std::exp(sigma), ExpSO3(omega), SimilarityV(omega, sigma) * upsilon);
}

Vector7d Sim3::Log() const {
  const Eigen::Vector3d omega = LogSO3(rotation);
  const double sigma = std::log(scale);
  Vector7d tangent;
  tangent.head<3>() = SimilarityV(omega, sigma).inverse() * translation;
  tangent.segment<3>(3) = omega;
  tangent(6) = sigma;
  return tangent;
}

}  // namespace arucoslam
