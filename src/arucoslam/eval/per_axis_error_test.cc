#include "arucoslam/eval/per_axis_error.h"

#include <gtest/gtest.h>

namespace arucoslam {
namespace {

TEST(PerAxisError, StatisticsAndSamplesAtChosenTimes) {
  Trajectory gt;
  Trajectory est;
  // Errors: x alternates +-0.1, y is 0.02 i, z is 0.
  for (int i = 0; i < 5; ++i) {
    const Eigen::Vector3d p(i, 2.0 * i, 1.0);
    gt.Add(10.0 + i, Rigid3(Eigen::Quaterniond::Identity(), p));
    est.Add(10.0 + i, Rigid3(Eigen::Quaterniond::Identity(),
                             p + Eigen::Vector3d(i % 2 ? 0.1 : -0.1, 0.02 * i, 0.0)));
  }
  PerAxisErrorOptions options;
  options.timestamps = {12.04, 20.0};
  const PerAxisError result = ComputePerAxisError(gt, est, options);
  EXPECT_EQ(result.count, 5u);
  EXPECT_NEAR(result.mean_abs.x(), 0.1, 1e-15);
  EXPECT_NEAR(result.std_abs.x(), 0.0, 1e-15);
  EXPECT_NEAR(result.mean_abs.y(), 0.04, 1e-15);              // mean of 0, .02 .. .08
  EXPECT_NEAR(result.std_abs.y(), std::sqrt(0.0008), 1e-15);  // population std
  EXPECT_NEAR(result.max_abs.y(), 0.08, 1e-15);
  EXPECT_EQ(result.mean_abs.z(), 0.0);
  ASSERT_EQ(result.samples.size(), 2u);
  EXPECT_TRUE(result.samples[0].found);
  EXPECT_EQ(result.samples[0].time, 12.0);
  EXPECT_NEAR(result.samples[0].abs_error.y(), 0.04, 1e-15);
  EXPECT_EQ(result.samples[0].gt_position, Eigen::Vector3d(2.0, 4.0, 1.0));
  EXPECT_FALSE(result.samples[1].found);  // 20 s is 6 s from the last pose
}

}  // namespace
}  // namespace arucoslam
