#include "arucoslam/util/median.h"

#include <gtest/gtest.h>

namespace arucoslam {
namespace {

TEST(Median, MiddleValueOrUpperOfTheTwoMiddleOnes) {
  EXPECT_EQ(Median({}), 0.0);
  EXPECT_EQ(Median({4.0}), 4.0);
  EXPECT_EQ(Median({5.0, -1.0, 3.0}), 3.0);
  EXPECT_EQ(Median({2.0, 8.0, 1.0, 4.0}), 4.0);
}

}  // namespace
}  // namespace arucoslam
