#include "arucoslam/geometry/pose_information.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace arucoslam {

double LeastCertainPositionSigma(const Matrix6d& information) {
  const Matrix6d off_diagonal = information - Matrix6d(information.diagonal().asDiagonal());
  if (off_diagonal.isZero(0.0)) {
    return 1.0 / std::sqrt(information.diagonal().head<3>().minCoeff());
  }
  const Matrix6d covariance = information.ldlt().solve(Matrix6d::Identity());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance.topLeftCorner<3, 3>(),
                                                             Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, eigen.eigenvalues().maxCoeff()));
}

Matrix6d WithCovarianceFloor(const Matrix6d& information,
                             const Eigen::Matrix<double, 6, 1>& floor_variances) {
  // (I^-1 + F)^-1 = I (I + F I)^-1 ... written symmetric: with S = F^(1/2),
  // (I^-1 + F)^-1 = S^-1 (S^-1 I^-1 S^-1 + 1)^-1 S^-1 = S^-1 (1 - (1 + S I S)^-1) S^-1,
  // where 1 + S I S is positive definite even when I is singular.
  const Eigen::Matrix<double, 6, 1> root = floor_variances.cwiseSqrt();
  const Matrix6d scaled = root.asDiagonal() * information * root.asDiagonal();
  const Matrix6d shifted = Matrix6d::Identity() + scaled;
  const Matrix6d inner = Matrix6d::Identity() - shifted.ldlt().solve(Matrix6d::Identity());
  const Eigen::Matrix<double, 6, 1> inverse_root = root.cwiseInverse();
  Matrix6d result = inverse_root.asDiagonal() * inner * inverse_root.asDiagonal();
  return 0.5 * (result + result.transpose());
}

}  // namespace arucoslam
