#include "arucoslam/geometry/world_motion_prior.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arucoslam {
namespace {

// Moving at 0.5 m/s along x while turning at 20 deg/s about the camera's y axis.
Rigid3 Truth(double t) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(20.0 * M_PI / 180.0 * t,
                                                     Eigen::Vector3d::UnitY())),
                Eigen::Vector3d(0.5 * t, 0.1, 1.0));
}

TEST(WorldMotionPrior, ConstantMotionIsExtrapolated) {
  WorldMotionPrior prior;
  for (int k = 0; k <= 10; ++k) prior.Add(0.033 * k, Truth(0.033 * k));
  const std::optional<Rigid3> predicted = prior.Predict(0.033 * 12);
  ASSERT_TRUE(predicted.has_value());
  const Rigid3 truth = Truth(0.033 * 12);
  EXPECT_LT((predicted->translation - truth.translation).norm(), 1e-9);
  EXPECT_LT(RotationAngle(predicted->rotation.inverse() * truth.rotation), 1e-9);
}

TEST(WorldMotionPrior, NoPredictionFromOldOrCloseFixes) {
  WorldMotionPrior prior;
  EXPECT_FALSE(prior.Predict(0.0).has_value());
  prior.Add(0.0, Truth(0.0));
  prior.Add(0.033, Truth(0.033));
  EXPECT_FALSE(prior.Predict(0.066).has_value());  // 33 ms of fixes: velocity too noisy
  prior.Add(0.15, Truth(0.15));
  EXPECT_TRUE(prior.Predict(0.2).has_value());
  EXPECT_FALSE(prior.Predict(0.5).has_value());  // 0.35 s after the last fix
  prior.Clear();
  EXPECT_FALSE(prior.Predict(0.2).has_value());
}

}  // namespace
}  // namespace arucoslam
