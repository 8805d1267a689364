#include "arucoslam/geometry/pose_information.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>

namespace arucoslam {
namespace {

TEST(IsotropicPoseInformation, InverseVariancesOnTheDiagonal) {
  const Matrix6d information = IsotropicPoseInformation(0.5, 0.1);
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(information(i, i), 4.0);     // 1 / 0.5^2
  for (int i = 3; i < 6; ++i) EXPECT_NEAR(information(i, i), 100.0, 1e-9);  // 1 / 0.1^2
  Matrix6d off_diagonal = information;
  off_diagonal.diagonal().setZero();
  EXPECT_EQ(off_diagonal.cwiseAbs().maxCoeff(), 0.0);
}

TEST(IsotropicPoseInformation, TighterSigmaWeighsMore) {
  EXPECT_GT(IsotropicPoseInformation(0.01, 0.1)(0, 0), IsotropicPoseInformation(0.02, 0.1)(0, 0));
  EXPECT_GT(IsotropicPoseInformation(0.1, 0.01)(5, 5), IsotropicPoseInformation(0.1, 0.02)(5, 5));
}

// A symmetric positive definite information with correlations between centre and rotation.
Matrix6d CorrelatedInformation() {
  Matrix6d a;
  a << 3, 1, 0, 2, 0, 1,  //
      0, 2, 1, 0, 1, 0,   //
      1, 0, 4, 1, 0, 2,   //
      0, 1, 0, 5, 1, 0,   //
      2, 0, 1, 0, 3, 1,   //
      0, 1, 0, 1, 0, 2;
  return a.transpose() * a + Matrix6d::Identity();
}

TEST(LeastCertainPositionSigma, DiagonalInformationGivesItsWeakestAxis) {
  Matrix6d information = IsotropicPoseInformation(0.02, 0.01);
  EXPECT_EQ(LeastCertainPositionSigma(information), 1.0 / std::sqrt(information(0, 0)));
  information(1, 1) = 1.0 / (0.05 * 0.05);
  EXPECT_NEAR(LeastCertainPositionSigma(information), 0.05, 1e-12);
}

TEST(LeastCertainPositionSigma, CorrelatedInformationGivesTheMarginalCovariancesLargestAxis) {
  const Matrix6d information = CorrelatedInformation();
  const Eigen::Matrix3d centre_covariance = information.inverse().topLeftCorner<3, 3>();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(centre_covariance);
  EXPECT_NEAR(LeastCertainPositionSigma(information), std::sqrt(eigen.eigenvalues()(2)), 1e-12);
  // Correlations make the marginal sigma larger than 1 / sqrt of the diagonal entries.
  EXPECT_GT(LeastCertainPositionSigma(information),
            1.0 / std::sqrt(information.diagonal().head<3>().minCoeff()));
}

TEST(WithCovarianceFloor, AddsTheFloorToTheCovariance) {
  const Matrix6d information = CorrelatedInformation();
  Eigen::Matrix<double, 6, 1> floor;
  floor << 1e-4, 2e-4, 1e-4, 4e-4, 1e-4, 3e-4;
  const Matrix6d expected = (information.inverse() + Matrix6d(floor.asDiagonal())).inverse();
  EXPECT_LT((WithCovarianceFloor(information, floor) - expected).norm(), 1e-9 * expected.norm());
}

TEST(WithCovarianceFloor, SingularInformationLeavesTheUnseenDirectionsAtZero) {
  // Only the centre's x is known (to 0.1 m); the floor is 0.01 m / 0.01 rad everywhere.
  Matrix6d information = Matrix6d::Zero();
  information(0, 0) = 100.0;
  const Eigen::Matrix<double, 6, 1> floor = Eigen::Matrix<double, 6, 1>::Constant(1e-4);
  const Matrix6d result = WithCovarianceFloor(information, floor);
  EXPECT_NEAR(result(0, 0), 1.0 / (0.01 + 1e-4), 1e-9);
  EXPECT_NEAR((result.bottomRightCorner<5, 5>().norm()), 0.0, 1e-9);
  // A firm measurement is held no tighter than the floor.
  information(0, 0) = 1e12;
  EXPECT_NEAR(WithCovarianceFloor(information, floor)(0, 0), 1e4, 1e-3);
}

}  // namespace
}  // namespace arucoslam
