#include "arucoslam/optim/position_prior_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace arucoslam {
namespace {

TEST(PositionPriorErrorTest, ZeroAtThePriorAndWhitenedOffIt) {
  const Rigid3 world_from_cam(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(4.0, -1.0, 0.6));
  const PositionPriorError error({0, Eigen::Vector3d(4.0, -1.0, 0.6), 0.2});
  Eigen::Vector3d residual;
  error.Evaluate(world_from_cam.Inverse(), &residual);
  EXPECT_LT(residual.norm(), 1e-12);
  // The camera 0.3 m further along world x, turned the other way: 1.5 sigmas along x only.
  const Rigid3 moved(Eigen::Quaterniond(Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitZ())),
                     Eigen::Vector3d(4.3, -1.0, 0.6));
  error.Evaluate(moved.Inverse(), &residual);
  EXPECT_NEAR(residual.x(), 1.5, 1e-12);
  EXPECT_NEAR(residual.y(), 0.0, 1e-12);
  EXPECT_NEAR(residual.z(), 0.0, 1e-12);
}

TEST(PositionPriorErrorTest, AnalyticJacobianMatchesNumericDifferences) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    Vector6d tangent;
    for (int k = 0; k < 6; ++k) tangent[k] = 2.0 * uniform(random);
    const Rigid3 pose = Rigid3::Exp(tangent);
    const PositionPriorError error(
        {0, Eigen::Vector3d(uniform(random), uniform(random), uniform(random)),
         0.05 + std::abs(uniform(random))});
    Eigen::Vector3d residual;
    PositionPriorPoseJacobian d_pose;
    error.Evaluate(pose, &residual, &d_pose);
    const double h = 1e-6;
    Eigen::Vector3d plus, minus;
    for (int k = 0; k < 6; ++k) {
      Vector6d delta = Vector6d::Zero();
      delta[k] = h;
      error.Evaluate(Rigid3::Exp(delta) * pose, &plus);
      error.Evaluate(Rigid3::Exp(-delta) * pose, &minus);
      EXPECT_LT(((plus - minus) / (2.0 * h) - d_pose.col(k)).norm(), 1e-5) << "pose " << k;
    }
  }
}

}  // namespace
}  // namespace arucoslam
