#include "arucoslam/geometry/pose_information.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace arucoslam
