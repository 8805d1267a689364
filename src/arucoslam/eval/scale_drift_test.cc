#include "arucoslam/eval/scale_drift.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "arucoslam/geometry/sim3.h"

namespace arucoslam {
namespace {

// The truth drives along x at 1 m/s for `seconds` (10 poses a second) after `turn_seconds`
// turning on the spot; the estimate covers each step times shrink(t) = 1 - rate * t and
// is then scaled by 3, turned and moved (an arbitrary monocular frame).
AssociatedTrajectories ShrinkingPairs(double rate, double seconds, double turn_seconds = 0.0) {
  const Sim3 est_from_gt(3.0, Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ())),
                         Eigen::Vector3d(1.0, 2.0, 0.0));
  AssociatedTrajectories pairs;
  Eigen::Vector3d gt_position = Eigen::Vector3d::Zero();
  Eigen::Vector3d shrunk_position = Eigen::Vector3d::Zero();
  const double step = 0.1;
  const int count = static_cast<int>(std::lround((turn_seconds + seconds) / step));
  for (int i = 0; i < count; ++i) {
    const double t = i / 10.0;  // exact multiples of 0.1 s, as the windows' bounds
    const bool turning = t < turn_seconds;
    const Eigen::Quaterniond heading(
        Eigen::AngleAxisd(turning ? t : turn_seconds, Eigen::Vector3d::UnitZ()));
    const Rigid3 gt(heading, gt_position);
    const Rigid3 shrunk(heading, shrunk_position);
    pairs.gt.Add(t, gt);
    pairs.est.Add(t, est_from_gt.TransformPose(shrunk));
    if (!turning) {
      const Eigen::Vector3d forward = heading * Eigen::Vector3d::UnitX();
      gt_position += step * forward;
      shrunk_position += step * (1.0 - rate * (t - turn_seconds)) * forward;
    }
  }
  return pairs;
}

TEST(ScaleDrift, FollowsAShrinkingEstimateWindowByWindow) {
  const double rate = 0.005;  // 20% smaller over 40 s
  const std::optional<ScaleDrift> drift = ComputeScaleDrift(ShrinkingPairs(rate, 40.0));
  ASSERT_TRUE(drift.has_value());
  ASSERT_EQ(drift->windows.size(), 5u);
  for (const ScaleDriftWindow& window : drift->windows) {
    const double middle = 0.5 * (window.start_s + window.end_s);
    EXPECT_NEAR(window.estimate_per_truth, 3.0 * (1.0 - rate * middle), 3e-3) << middle;
    EXPECT_EQ(window.num_pairs, 80u);
  }
  EXPECT_NEAR(drift->last_over_first, (1.0 - rate * 36.0) / (1.0 - rate * 4.0) - 1.0, 2e-3);
  EXPECT_DOUBLE_EQ(drift->max, drift->windows.front().estimate_per_truth);
  EXPECT_DOUBLE_EQ(drift->min, drift->windows.back().estimate_per_truth);
}

TEST(ScaleDrift, AMetricTrajectoryKeepsScaleOne) {
  const std::optional<ScaleDrift> drift = ComputeScaleDrift(ShrinkingPairs(0.0, 24.0));
  ASSERT_TRUE(drift.has_value());
  for (const ScaleDriftWindow& window : drift->windows) {
    EXPECT_NEAR(window.estimate_per_truth, 3.0, 1e-9);
  }
  EXPECT_NEAR(drift->last_over_first, 0.0, 1e-9);
}

TEST(ScaleDrift, WindowsTurningOnTheSpotAreSkipped) {
  // 8 s of turning without moving, then 24 s of driving: three windows, not four.
  const std::optional<ScaleDrift> drift = ComputeScaleDrift(ShrinkingPairs(0.0, 24.0, 8.0));
  ASSERT_TRUE(drift.has_value());
  ASSERT_EQ(drift->windows.size(), 3u);
  EXPECT_NEAR(drift->windows.front().start_s, 8.0, 1e-9);
}

TEST(ScaleDrift, TooShortOrBadOptions) {
  EXPECT_FALSE(ComputeScaleDrift(ShrinkingPairs(0.0, 7.0)).has_value());  // one window
  EXPECT_FALSE(ComputeScaleDrift(AssociatedTrajectories{}).has_value());
  ScaleDriftOptions bad;
  bad.window_s = 0.0;
  EXPECT_THROW(ComputeScaleDrift(ShrinkingPairs(0.0, 24.0), bad), std::invalid_argument);
}

}  // namespace
}  // namespace arucoslam
