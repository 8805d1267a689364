#include "arucoslam/eval/statistics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arucoslam {
namespace {

TEST(Statistics, MatchesHandComputedValues) {
  const ErrorStatistics s = ComputeErrorStatistics({3.0, 1.0, 4.0, 2.0});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));  // population: (2.25+0.25+0.25+2.25)/4
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(ComputeErrorStatistics({5.0, 1.0, 3.0}).median, 3.0);
  EXPECT_EQ(ComputeErrorStatistics({}).count, 0u);
}

TEST(Statistics, PercentileInterpolatesLinearly) {
  const std::vector<double> values = {10.0, 0.0, 20.0, 30.0, 40.0};
  EXPECT_DOUBLE_EQ(Percentile(values, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(Percentile(values, 100.0), 40.0);
  EXPECT_DOUBLE_EQ(Percentile(values, 90.0), 36.0);  // position 3.6
  EXPECT_DOUBLE_EQ(Percentile(values, 50.0), 20.0);
  EXPECT_DOUBLE_EQ(Percentile({}, 50.0), 0.0);
}

}  // namespace
}  // namespace arucoslam
