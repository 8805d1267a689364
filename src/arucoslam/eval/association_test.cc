#include "arucoslam/eval/association.h"

#include <gtest/gtest.h>

namespace arucoslam {
namespace {

Trajectory Stamps(const std::vector<double>& stamps) {
  Trajectory trajectory;
  for (double t : stamps)
    trajectory.Add(t, Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(t, 0.0, 0.0)));
  return trajectory;
}

TEST(Association, ClosestStampWithinMaxDifference) {
  const Trajectory gt = Stamps({0.0, 0.1, 0.2, 0.3, 0.4, 0.5});
  const Trajectory est = Stamps({0.104, 0.26, 0.391});
  const AssociatedTrajectories pairs = AssociateByTime(gt, est, AssociationOptions{0.01});
  // 0.26 is 0.04 from both 0.2 and 0.3: dropped. 0.104 -> 0.1, 0.391 -> 0.4.
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs.gt_indices, (std::vector<std::size_t>{1, 4}));
  EXPECT_EQ(pairs.est_indices, (std::vector<std::size_t>{0, 2}));
  EXPECT_DOUBLE_EQ(pairs.gt.poses[1].translation.x(), 0.4);
  EXPECT_DOUBLE_EQ(pairs.est.timestamps[1], 0.391);
}

TEST(Association, BoundaryIsInclusiveAndTieTakesTheEarlierStamp) {
  const Trajectory gt = Stamps({1.0, 2.0, 3.0, 4.0});
  const Trajectory est = Stamps({1.5, 3.25});
  // 1.5 is 0.5 from 1.0 and from 2.0: the first (1.0) wins, as numpy's argmin.
  const AssociatedTrajectories pairs = AssociateByTime(gt, est, AssociationOptions{0.5});
  EXPECT_EQ(pairs.gt_indices, (std::vector<std::size_t>{0, 2}));
  const AssociatedTrajectories narrower = AssociateByTime(gt, est, AssociationOptions{0.25});
  ASSERT_EQ(narrower.size(), 1u);  // only 3.25 -> 3.0 (difference exactly 0.25)
  EXPECT_EQ(narrower.gt_indices[0], 2u);
}

TEST(Association, TheShorterTrajectoryIsWalked) {
  // The estimate is longer here: evo walks the ground truth and may use an estimated pose
  // for several ground-truth poses.
  const Trajectory gt = Stamps({0.0, 0.003});
  const Trajectory est = Stamps({-0.5, 0.001, 0.5});
  const AssociatedTrajectories pairs = AssociateByTime(gt, est, AssociationOptions{0.01});
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs.est_indices, (std::vector<std::size_t>{1, 1}));
  EXPECT_EQ(pairs.gt_indices, (std::vector<std::size_t>{0, 1}));
}

TEST(Association, RepeatedStampsMatchTheFirstOfTheRun) {
  const Trajectory gt = Stamps({0.0, 1.0, 1.0, 2.0, 3.0, 4.0});
  const Trajectory est = Stamps({1.004, 1.004});
  const AssociatedTrajectories pairs = AssociateByTime(gt, est, AssociationOptions{0.01});
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs.gt_indices, (std::vector<std::size_t>{1, 1}));
}

TEST(Association, NoOverlapGivesNoPairs) {
  const AssociatedTrajectories pairs =
      AssociateByTime(Stamps({0.0, 1.0}), Stamps({5.0, 6.0}), AssociationOptions{0.01});
  EXPECT_EQ(pairs.size(), 0u);
}

TEST(Association, ByIndexNeedsEqualLengths) {
  EXPECT_EQ(AssociateByIndex(Stamps({0, 1, 2}), Stamps({5, 6, 7})).size(), 3u);
  EXPECT_THROW(AssociateByIndex(Stamps({0, 1}), Stamps({0})), std::invalid_argument);
}

}  // namespace
}  // namespace arucoslam
