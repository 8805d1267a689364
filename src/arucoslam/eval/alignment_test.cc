#include "arucoslam/eval/alignment.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arucoslam {
namespace {

// A helix in the estimate frame and its image under a known similarity (the truth).
AssociatedTrajectories HelixPairs(const Sim3& gt_from_est, int count) {
  AssociatedTrajectories pairs;
  for (int i = 0; i < count; ++i) {
    const double t = 0.1 * i;
    const Rigid3 est(Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * t, Eigen::Vector3d::UnitZ())),
                     Eigen::Vector3d(std::cos(t), std::sin(t), 0.2 * t));
    pairs.est.Add(t, est);
    pairs.gt.Add(t, gt_from_est.TransformPose(est));
  }
  return pairs;
}

const Sim3 kTruth(2.5,
                  Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
                  Eigen::Vector3d(4.0, -1.0, 0.5));

TEST(Alignment, Sim3RecoversAKnownSimilarity) {
  const AssociatedTrajectories pairs = HelixPairs(kTruth, 50);
  AlignmentOptions options;
  options.mode = AlignmentMode::kSim3;
  const auto result = ComputeAlignment(pairs, options);
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->num_fitted, 50u);
  EXPECT_NEAR(result->gt_from_est.scale, 2.5, 1e-12);
  EXPECT_NEAR(result->gt_from_est.rotation.angularDistance(kTruth.rotation), 0.0, 1e-12);
  EXPECT_NEAR((result->gt_from_est.translation - kTruth.translation).norm(), 0.0, 1e-11);
  const Trajectory aligned = ApplyAlignment(result->gt_from_est, pairs.est);
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    EXPECT_NEAR((aligned.poses[i].translation - pairs.gt.poses[i].translation).norm(), 0.0, 1e-11);
    EXPECT_NEAR(aligned.poses[i].rotation.angularDistance(pairs.gt.poses[i].rotation), 0.0, 1e-12);
  }
}

TEST(Alignment, Se3KeepsScaleOneAndNoneIsIdentity) {
  const Sim3 rigid(1.0, kTruth.rotation, kTruth.translation);
  const AssociatedTrajectories pairs = HelixPairs(rigid, 30);
  AlignmentOptions options;
  options.mode = AlignmentMode::kSe3;
  const auto se3 = ComputeAlignment(pairs, options);
  ASSERT_TRUE(se3.has_value());
  EXPECT_EQ(se3->gt_from_est.scale, 1.0);
  EXPECT_NEAR((se3->gt_from_est.translation - rigid.translation).norm(), 0.0, 1e-11);
  options.mode = AlignmentMode::kNone;
  const auto none = ComputeAlignment(pairs, options);
  ASSERT_TRUE(none.has_value());
  EXPECT_EQ(none->gt_from_est.ToMatrix(), Eigen::Matrix4d::Identity());
  EXPECT_EQ(none->num_fitted, 0u);
}

TEST(Alignment, FirstPosesAndTimeWindowSelectTheFit) {
  AssociatedTrajectories pairs = HelixPairs(kTruth, 40);
  // Corrupt the second half: a fit on the first 20 pairs must not see it.
  for (std::size_t i = 20; i < pairs.size(); ++i) {
    pairs.gt.poses[i].translation += Eigen::Vector3d(3.0, 0.0, 0.0);
  }
  AlignmentOptions options;
  options.mode = AlignmentMode::kSim3;
  options.first_poses = 20;
  const auto first = ComputeAlignment(pairs, options);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->num_fitted, 20u);
  EXPECT_NEAR(first->gt_from_est.scale, 2.5, 1e-12);
  options.first_poses = 0;
  options.window_start = 0.45;  // pairs 5..19 (t = 0.1 i)
  options.window_end = 1.95;
  const auto window = ComputeAlignment(pairs, options);
  ASSERT_TRUE(window.has_value());
  EXPECT_EQ(window->num_fitted, 15u);
  EXPECT_NEAR(window->gt_from_est.scale, 2.5, 1e-12);
  const auto all = ComputeAlignment(pairs, AlignmentOptions{AlignmentMode::kSim3});
  ASSERT_TRUE(all.has_value());
  EXPECT_GT(std::abs(all->gt_from_est.scale - 2.5), 1e-3);  // the corruption shows
}

TEST(Alignment, TooFewOrDegeneratePairsGiveNothing) {
  AlignmentOptions options;
  options.mode = AlignmentMode::kSe3;
  EXPECT_FALSE(ComputeAlignment(HelixPairs(kTruth, 2), options).has_value());
  AssociatedTrajectories same_point;
  for (int i = 0; i < 5; ++i) {
    same_point.gt.Add(i, Rigid3());
    same_point.est.Add(i, Rigid3());
  }
  EXPECT_FALSE(ComputeAlignment(same_point, options).has_value());
  options.window_start = 100.0;  // no pair inside
  EXPECT_FALSE(ComputeAlignment(HelixPairs(kTruth, 10), options).has_value());
}

TEST(Alignment, ParsesModeNames) {
  EXPECT_EQ(ParseAlignmentMode("SE3"), AlignmentMode::kSe3);
  EXPECT_EQ(ParseAlignmentMode("sim3"), AlignmentMode::kSim3);
  EXPECT_EQ(ParseAlignmentMode("none"), AlignmentMode::kNone);
  EXPECT_FALSE(ParseAlignmentMode("affine").has_value());
  AlignmentOptions bad;
  bad.window_start = 2.0;
  bad.window_end = 1.0;
  EXPECT_FALSE(bad.Check());
}

}  // namespace
}  // namespace arucoslam
