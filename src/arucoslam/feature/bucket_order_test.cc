#include "arucoslam/feature/bucket_order.h"

#include <gtest/gtest.h>

namespace arucoslam {
namespace {

TEST(SortIntoBuckets, GroupsByBucketKeepingIndexOrderAndLeavesOutNegatives) {
  const BucketOrder order = SortIntoBuckets({2, 0, -1, 2, 1, 0, -3}, 4);
  EXPECT_EQ(order.members, (std::vector<int>{1, 5, 4, 0, 3}));
  EXPECT_EQ(order.begin, (std::vector<int>{0, 2, 3, 5, 5}));
}

TEST(SortIntoBuckets, NothingToSortGivesEmptyBuckets) {
  const BucketOrder order = SortIntoBuckets({-1, -1}, 3);
  EXPECT_TRUE(order.members.empty());
  EXPECT_EQ(order.begin, (std::vector<int>{0, 0, 0, 0}));
}

}  // namespace
}  // namespace arucoslam
