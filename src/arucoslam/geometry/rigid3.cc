#include "arucoslam/geometry/rigid3.h"

#include <cmath>

namespace arucoslam {
namespace {
constexpr double kSmallAngle = 1e-8;
// Below this angle the SE(3) Jacobian coefficients use their Taylor series: the closed
// forms cancel catastrophically there (the truncation error is below 1e-17).
constexpr double kSeriesAngle = 1e-2;

// (1 - cos theta) / theta^2, written with the half angle so it keeps full precision.
double OneMinusCosOverTheta2(double theta) {
  if (theta < kSmallAngle) return 0.5;
  const double sinc_half = std::sin(0.5 * theta) / (0.5 * theta);
  return 0.5 * sinc_half * sinc_half;
}

// (theta - sin theta) / theta^3.
double ThetaMinusSinOverTheta3(double theta) {
  const double theta2 = theta * theta;
  if (theta < kSeriesAngle) return 1.0 / 6.0 - theta2 / 120.0 + theta2 * theta2 / 5040.0;
  return (theta - std::sin(theta)) / (theta2 * theta);
}

// (1 - (theta / 2) cot(theta / 2)) / theta^2, the coefficient of the inverse left Jacobian.
double InverseLeftJacobianCoefficient(double theta) {
  const double theta2 = theta * theta;
  if (theta < kSeriesAngle) return 1.0 / 12.0 + theta2 / 720.0 + theta2 * theta2 / 30240.0;
  const double half = 0.5 * theta;
  return (1.0 - half * std::cos(half) / std::sin(half)) / theta2;
}
}  // namespace

Eigen::Matrix3d Hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Quaterniond ExpSO3(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  if (theta < kSmallAngle) {
    Eigen::Quaterniond q(1.0, 0.5 * omega.x(), 0.5 * omega.y(), 0.5 * omega.z());
    return q.normalized();
  }
  return Eigen::Quaterniond(Eigen::AngleAxisd(theta, omega / theta));
}

Eigen::Vector3d LogSO3(const Eigen::Quaterniond& rotation) {
  Eigen::Quaterniond q = rotation.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // shortest rotation
  const double sin_half = q.vec().norm();
  if (sin_half < kSmallAngle) return 2.0 * q.vec() / q.w();
  const double theta = 2.0 * std::atan2(sin_half, q.w());
  return theta * q.vec() / sin_half;
}

double RotationAngle(const Eigen::Quaterniond& rotation) { return LogSO3(rotation).norm(); }

Rigid3 Rigid3::FromMatrix(const Eigen::Matrix4d& matrix) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(matrix.topLeftCorner<3, 3>(),
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  if (rotation.determinant() < 0.0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) *= -1.0;
    rotation = u * svd.matrixV().transpose();
  }
  return Rigid3(rotation, matrix.topRightCorner<3, 1>());
}

Eigen::Matrix4d Rigid3::ToMatrix() const {
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
  matrix.topLeftCorner<3, 3>() = RotationMatrix();
  matrix.topRightCorner<3, 1>() = translation;
  return matrix;
}

Rigid3 Rigid3::Inverse() const {
  const Eigen::Quaterniond inverse_rotation = rotation.conjugate();
  return Rigid3(inverse_rotation, -(inverse_rotation * translation));
}

Rigid3 Rigid3::Exp(const Vector6d& tangent) {
  const Eigen::Vector3d upsilon = tangent.head<3>();
  const Eigen::Vector3d omega = tangent.tail<3>();
  const double theta = omega.norm();
  const Eigen::Matrix3d omega_hat = Hat(omega);
  const Eigen::Matrix3d left_jacobian = Eigen::Matrix3d::Identity() +
                                        OneMinusCosOverTheta2(theta) * omega_hat +
                                        ThetaMinusSinOverTheta3(theta) * omega_hat * omega_hat;
  return Rigid3(ExpSO3(omega), left_jacobian * upsilon);
}

Vector6d Rigid3::Log() const {
  const Eigen::Vector3d omega = LogSO3(rotation);
  const double theta = omega.norm();
  const Eigen::Matrix3d omega_hat = Hat(omega);
  const Eigen::Matrix3d inverse_left_jacobian =
      Eigen::Matrix3d::Identity() - 0.5 * omega_hat +
      InverseLeftJacobianCoefficient(theta) * omega_hat * omega_hat;
  Vector6d tangent;
  tangent.head<3>() = inverse_left_jacobian * translation;
  tangent.tail<3>() = omega;
  return tangent;
}

Eigen::Matrix<double, 6, 6> Rigid3::Adjoint() const {
  Eigen::Matrix<double, 6, 6> adjoint = Eigen::Matrix<double, 6, 6>::Zero();
  const Eigen::Matrix3d r = RotationMatrix();
  adjoint.topLeftCorner<3, 3>() = r;
  adjoint.topRightCorner<3, 3>() = Hat(translation) * r;
  adjoint.bottomRightCorner<3, 3>() = r;
  return adjoint;
}

Rigid3 Interpolate(const Rigid3& a, const Rigid3& b, double t) {
  return Rigid3(a.rotation.slerp(t, b.rotation), (1.0 - t) * a.translation + t * b.translation);
}

}  // namespace arucoslam
