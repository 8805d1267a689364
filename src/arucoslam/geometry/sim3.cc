#include "arucoslam/geometry/sim3.h"

#include <cmath>

namespace arucoslam {
namespace {

constexpr double kEpsilon = 1e-8;

// The matrix W with t = W * upsilon in exp(upsilon, omega, sigma) (Strasdat's thesis, A.5).
Eigen::Matrix3d SimilarityV(const Eigen::Vector3d& omega, double sigma) {
  const double theta = omega.norm();
  const Eigen::Matrix3d omega_hat = Hat(omega);
  const Eigen::Matrix3d omega_hat2 = omega_hat * omega_hat;
  const double scale = std::exp(sigma);
  double a, b, c;
  if (std::abs(sigma) < kEpsilon) {
    c = 1.0;
    if (theta < kEpsilon) {
      a = 0.5;
      b = 1.0 / 6.0;
    } else {
      const double theta2 = theta * theta;
      a = (1.0 - std::cos(theta)) / theta2;
      b = (theta - std::sin(theta)) / (theta2 * theta);
    }
  } else {
    c = (scale - 1.0) / sigma;
    if (theta < kEpsilon) {
      const double sigma2 = sigma * sigma;
      a = ((sigma - 1.0) * scale + 1.0) / sigma2;
      b = (scale * 0.5 * sigma2 + scale - 1.0 - sigma * scale) / (sigma2 * sigma);
    } else {
      const double theta2 = theta * theta;
      const double sin_theta = std::sin(theta);
      const double cos_theta = std::cos(theta);
      const double denominator = sigma * sigma + theta2;
      a = (scale * sin_theta * sigma + (1.0 - scale * cos_theta) * theta) /
          (theta * denominator);
      b = (c - ((scale * cos_theta - 1.0) * sigma + scale * sin_theta * theta) / denominator) /
          theta2;
    }
  }
  return c * Eigen::Matrix3d::Identity() + a * omega_hat + b * omega_hat2;
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
