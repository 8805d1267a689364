#include "arucoslam/eval/pose_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace arucoslam {
namespace {

// Straight line along x at 1 m/s, 10 Hz, turning slowly about z.
Trajectory Line(int count) {
  Trajectory trajectory;
  for (int i = 0; i < count; ++i) {
    trajectory.Add(0.1 * i,
                   Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * i, Eigen::Vector3d::UnitZ())),
                          Eigen::Vector3d(0.1 * i, 0.0, 0.0)));
  }
  return trajectory;
}

TEST(PoseError, AbsoluteErrorOfAKnownOffset) {
  const Trajectory gt = Line(10);
  Trajectory est = gt;
  const Eigen::Quaterniond tilt(
      Eigen::AngleAxisd(2.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitX()));
  for (Rigid3& pose : est.poses) {
    pose.translation += Eigen::Vector3d(0.03, -0.04, 0.0);  // 5 cm
    pose.rotation = pose.rotation * tilt;                   // 2 degrees
  }
  for (double e : AbsolutePoseErrors(gt, est, PoseRelation::kTranslation)) {
    EXPECT_NEAR(e, 0.05, 1e-15);
  }
  for (double e : AbsolutePoseErrors(gt, est, PoseRelation::kRotationAngleDeg)) {
    EXPECT_NEAR(e, 2.0, 1e-12);
  }
  for (double e : AbsolutePoseErrors(gt, est, PoseRelation::kRotationAngleRad)) {
    EXPECT_NEAR(e, 2.0 * std::numbers::pi / 180.0, 1e-14);
  }
  // Full: || P^-1 Q - I ||_F of a pure rotation R by angle a and a translation u:
  // ||R - I||_F^2 = 4 (1 - cos a), plus |u|^2 (u = -R^T-rotated offset, same norm).
  const double a = 2.0 * std::numbers::pi / 180.0;
  const double expected = std::sqrt(4.0 * (1.0 - std::cos(a)) + 0.05 * 0.05);
  for (double e : AbsolutePoseErrors(gt, est, PoseRelation::kFullTransformation)) {
    EXPECT_NEAR(e, expected, 1e-12);
  }
}

TEST(PoseError, RelativeErrorIgnoresAGlobalTransformAndSeesDrift) {
  const Trajectory gt = Line(21);
  Trajectory moved = gt;
  const Rigid3 world_change(
      Eigen::Quaterniond(Eigen::AngleAxisd(1.0, Eigen::Vector3d(1, 1, 0).normalized())),
      Eigen::Vector3d(5, 6, 7));
  for (Rigid3& pose : moved.poses) pose = world_change * pose;
  const IndexPairs pairs = RelativeIndexPairs(moved, RelativeErrorOptions{});
  ASSERT_EQ(pairs.size(), 20u);
  for (double e : RelativePoseErrors(gt, moved, pairs, PoseRelation::kTranslation)) {
    EXPECT_NEAR(e, 0.0, 1e-12);
  }
  // 1% scale drift: each 0.1 m step is 0.101 m long -> 1 mm per step.
  Trajectory drifting = gt;
  for (Rigid3& pose : drifting.poses) pose.translation *= 1.01;
  for (double e : RelativePoseErrors(gt, drifting, pairs, PoseRelation::kTranslation)) {
    EXPECT_NEAR(e, 0.001, 1e-12);
  }
}

TEST(PoseError, FramePairs) {
  const Trajectory t = Line(7);
  RelativeErrorOptions options;
  options.delta = 3;
  EXPECT_EQ(RelativeIndexPairs(t, options), (IndexPairs{{0, 3}, {3, 6}}));
  options.all_pairs = true;
  EXPECT_EQ(RelativeIndexPairs(t, options), (IndexPairs{{0, 3}, {1, 4}, {2, 5}, {3, 6}}));
}

TEST(PoseError, PathPairsFollowEvo) {
  // Steps of 0.1 m: path reaches 0.25 m at index 3 (0.3), then again 3 steps later.
  const Trajectory t = Line(11);
  RelativeErrorOptions options;
  options.delta = 0.25;
  options.unit = DeltaUnit::kMeters;
  EXPECT_EQ(RelativeIndexPairs(t, options), (IndexPairs{{3, 6}, {6, 9}}));
  // All pairs: j with path closest to 0.25 from i (0.2 and 0.3 tie: the first), within 10%.
  options.all_pairs = true;
  EXPECT_TRUE(RelativeIndexPairs(t, options).empty());  // |0.2 - 0.25| > 0.025
  options.delta = 0.3;
  const IndexPairs all = RelativeIndexPairs(t, options);
  ASSERT_EQ(all.size(), 8u);
  EXPECT_EQ(all.front(), (std::pair<std::size_t, std::size_t>{0, 3}));
  EXPECT_EQ(all.back(), (std::pair<std::size_t, std::size_t>{7, 10}));
}

TEST(PoseError, TimePairs) {
  const Trajectory t = Line(11);  // 10 Hz
  RelativeErrorOptions options;
  options.delta = 0.45;
  options.unit = DeltaUnit::kSeconds;
  EXPECT_EQ(RelativeIndexPairs(t, options), (IndexPairs{{5, 10}}));
  options.delta = 0.5;
  options.all_pairs = true;
  const IndexPairs all = RelativeIndexPairs(t, options);
  ASSERT_EQ(all.size(), 6u);
  EXPECT_EQ(all[2], (std::pair<std::size_t, std::size_t>{2, 7}));
}

TEST(PoseError, OptionsCheck) {
  RelativeErrorOptions options;
  options.delta = 1.5;  // frames must be whole
  EXPECT_FALSE(options.Check());
  options.unit = DeltaUnit::kMeters;
  EXPECT_TRUE(options.Check());
  options.delta = 0.0;
  EXPECT_FALSE(options.Check());
}

}  // namespace
}  // namespace arucoslam
