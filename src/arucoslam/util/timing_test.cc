#include "arucoslam/util/timing.h"

#include <gtest/gtest.h>

namespace arucoslam {
namespace {

TEST(TimingStats, SummaryMatchesOrderStatistics) {
  TimingStats stats;
  for (int i = 1; i <= 21; ++i) stats.Add(static_cast<double>(i));
  const TimingSummary summary = stats.Summarize();
  EXPECT_EQ(summary.count, 21u);
  EXPECT_DOUBLE_EQ(summary.mean, 11.0);
  EXPECT_DOUBLE_EQ(summary.median, 11.0);
  EXPECT_DOUBLE_EQ(summary.p95, 20.0);  // position 0.95 * 20 = 19 -> value 20
  EXPECT_DOUBLE_EQ(summary.max, 21.0);
}

TEST(TimingStats, EmptyGivesZeroCount) {
  EXPECT_EQ(TimingStats().Summarize().count, 0u);
}

TEST(PeakMemory, IsPositive) { EXPECT_GT(PeakMemoryBytes(), 0u); }

}  // namespace
}  // namespace arucoslam
