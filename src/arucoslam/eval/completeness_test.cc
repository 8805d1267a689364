#include "arucoslam/eval/completeness.h"

#include <gtest/gtest.h>

namespace arucoslam {
namespace {

Trajectory Stamps(double start, double end, double step) {
  Trajectory trajectory;
  for (double t = start; t <= end + 1e-9; t += step) trajectory.Add(t, Rigid3());
  return trajectory;
}

TEST(Completeness, FullCoverage) {
  const Trajectory gt = Stamps(0.0, 10.0, 0.01);
  const Completeness c = ComputeCompleteness(gt, Stamps(0.0, 10.0, 0.1), {});
  EXPECT_NEAR(c.gt_duration, 10.0, 1e-9);
  EXPECT_NEAR(c.covered_fraction, 1.0, 1e-9);
  EXPECT_EQ(c.num_gaps, 0);
  EXPECT_NEAR(c.max_gap_used, 0.3, 1e-9);  // 3 x the 0.1 s median interval
}

TEST(Completeness, LostInTheMiddleAndLateStart) {
  const Trajectory gt = Stamps(0.0, 10.0, 0.01);
  Trajectory est;
  for (const Trajectory& part : {Stamps(1.0, 4.0, 0.1), Stamps(6.5, 10.0, 0.1)}) {
    for (std::size_t i = 0; i < part.size(); ++i) est.Add(part.timestamps[i], part.poses[i]);
  }
  const Completeness c = ComputeCompleteness(gt, est, {});
  // Covered: 1..4 and 6.5..10 = 6.5 s of 10 s.
  EXPECT_NEAR(c.covered_duration, 6.5, 1e-6);
  EXPECT_NEAR(c.covered_fraction, 0.65, 1e-7);
  EXPECT_NEAR(c.longest_gap, 2.5, 1e-6);
  EXPECT_NEAR(c.longest_gap_start, 4.0, 1e-6);
  EXPECT_EQ(c.num_gaps, 2);  // 0..1 and 4..6.5
}

TEST(Completeness, ExplicitThresholdAndEstimateOutsideTheSpan) {
  const Trajectory gt = Stamps(0.0, 2.0, 0.5);
  // Poses every 0.5 s from -1 to 3: clipped to the 2 s span, all covered with a 0.6 s gap
  // threshold, nothing covered with 0.4 s.
  CompletenessOptions options;
  options.max_gap = 0.6;
  EXPECT_NEAR(ComputeCompleteness(gt, Stamps(-1.0, 3.0, 0.5), options).covered_fraction, 1.0,
              1e-12);
  options.max_gap = 0.4;
  const Completeness none = ComputeCompleteness(gt, Stamps(-1.0, 3.0, 0.5), options);
  EXPECT_NEAR(none.covered_fraction, 0.0, 1e-12);
  EXPECT_EQ(ComputeCompleteness(gt, Trajectory{}, options).longest_gap, 2.0);
}

}  // namespace
}  // namespace arucoslam
