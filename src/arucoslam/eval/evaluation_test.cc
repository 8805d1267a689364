#include "arucoslam/eval/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

// A 20 s loop at 20 Hz in the world.
Trajectory Loop() {
  Trajectory gt;
  for (int i = 0; i <= 400; ++i) {
    const double t = 100.0 + 0.05 * i;
    const double a = 2.0 * M_PI * (t - 100.0) / 20.0;
    gt.Add(t, Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ())),
                     Eigen::Vector3d(5.0 * std::cos(a), 5.0 * std::sin(a), 1.0)));
  }
  return gt;
}

std::string ErrorOf(const Trajectory& gt, const Trajectory& est) {
  try {
    EvaluateTrajectory(gt, est, "x", "est.txt", EvaluationOptions{});
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(Evaluation, MonocularEstimateAtHalfScaleWithAConstantOffset) {
  const Trajectory gt = Loop();
  // The estimate: every other pose, 2 ms late, at half scale in a frame turned 30 degrees,
  // plus a constant 2 cm error in world z. Lost between 5 and 8 s.
  const Sim3 est_from_gt(0.5, Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ())),
                         Eigen::Vector3d(1.0, 2.0, 0.0));
  Trajectory est;
  for (std::size_t i = 0; i < gt.size(); i += 2) {
    const double since_start = gt.timestamps[i] - 100.0;
    if (since_start > 5.0 && since_start < 8.0) continue;
    Rigid3 pose = gt.poses[i];
    pose.translation.z() += 0.02;
    est.Add(gt.timestamps[i] + 0.002, est_from_gt.TransformPose(pose));
  }
  EvaluationOptions options;
  options.alignment.mode = AlignmentMode::kSim3;
  options.per_axis.timestamps = {110.0};
  const TrajectoryEvaluation e = EvaluateTrajectory(gt, est, "mono", "est.txt", options);
  EXPECT_EQ(e.num_gt_poses, 401u);
  EXPECT_EQ(e.pairs.size(), est.size());
  EXPECT_NEAR(e.sim3_scale, 2.0, 1e-9);
  EXPECT_NEAR(e.scale_error, 1.0, 1e-9);
  // A constant offset is absorbed by the alignment's translation.
  EXPECT_NEAR(e.ape_translation.rmse, 0.0, 1e-9);
  EXPECT_NEAR(e.ape_rotation_deg.max, 0.0, 1e-6);
  EXPECT_NEAR(e.relative[0].translation.max, 0.0, 1e-9);
  EXPECT_NEAR(e.per_axis.mean_abs.norm(), 0.0, 1e-9);
  ASSERT_EQ(e.per_axis.samples.size(), 1u);
  EXPECT_TRUE(e.per_axis.samples[0].found);
  // Lost from 5.0 to 8.0 s (last pose before at 5.0, first after at 8.0): 3 s of 20 s; the
  // 2 ms delay leaves the first 2 ms uncovered too.
  EXPECT_NEAR(e.completeness.longest_gap, 3.0, 1e-6);
  EXPECT_NEAR(e.completeness.covered_fraction, (20.0 - 3.0 - 0.002) / 20.0, 1e-9);

  // Without alignment the same estimate is far off; with SE(3) the scale remains wrong.
  options.alignment.mode = AlignmentMode::kNone;
  const TrajectoryEvaluation raw = EvaluateTrajectory(gt, est, "mono", "est.txt", options);
  EXPECT_GT(raw.ape_translation.rmse, 1.0);
  EXPECT_NEAR(raw.sim3_scale, 2.0, 1e-9);  // reported whatever the alignment
  options.alignment.mode = AlignmentMode::kSe3;
  const TrajectoryEvaluation rigid = EvaluateTrajectory(gt, est, "mono", "est.txt", options);
  EXPECT_NEAR(rigid.ape_translation.mean, 2.5, 0.05);  // radius 5 m seen as 2.5 m
}

TEST(Evaluation, WorldOffsetWithoutAlignmentIsMeasured) {
  const Trajectory gt = Loop();
  Trajectory est = gt;
  for (Rigid3& pose : est.poses) pose.translation += Eigen::Vector3d(0.0, 0.0, 0.1);
  const TrajectoryEvaluation e = EvaluateTrajectory(gt, est, "offset", "est.txt", {});
  EXPECT_NEAR(e.ape_translation.rmse, 0.1, 1e-12);
  EXPECT_NEAR(e.ape_translation.min, 0.1, 1e-12);
  EXPECT_NEAR(e.per_axis.mean_abs.z(), 0.1, 1e-12);
  EXPECT_NEAR(e.per_axis.mean_abs.x(), 0.0, 1e-12);
  EXPECT_NEAR(e.completeness.covered_fraction, 1.0, 1e-9);
}

TEST(Evaluation, BadInputIsAnInputError) {
  const Trajectory gt = Loop();
  Trajectory late;
  for (int i = 0; i < 10; ++i) late.Add(500.0 + i, Rigid3());
  EXPECT_NE(ErrorOf(gt, late).find("est.txt: no pose within 0.01 s of a ground-truth pose"),
            std::string::npos);
  Trajectory two;
  two.Add(100.0, Rigid3());
  two.Add(100.05, Rigid3());
  EXPECT_EQ(ErrorOf(gt, two),
            "est.txt: only 2 pose(s) associated with the ground truth; at least 3 are needed");
  EXPECT_EQ(ErrorOf(gt, Trajectory{}), "est.txt: empty trajectory");
}

}  // namespace
}  // namespace arucoslam

namespace arucoslam {
namespace {

TEST(Evaluation, OptionsCheckSaysWhichValueIsWrong) {
  EvaluationOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;
  options.relative.push_back(RelativeErrorOptions{});
  options.relative[1].relative_tolerance = -0.5;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "relative[1].relative_tolerance must be >= 0, is -0.5");
  options = {};
  options.association.max_time_difference = -1.0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "association.max_time_difference must be >= 0, is -1");
}

}  // namespace
}  // namespace arucoslam
