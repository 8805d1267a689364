// Keypoint-only SLAM on real driving: `run --no-markers --blocking` over the first 160 frames
// of KITTI odometry 07 (a car turning out of a junction, then 90 m of street). Holds the share
// of frames posed and the Sim(3) ATE against the official poses; skipped without the data.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "arucoslam/eval/alignment.h"
#include "arucoslam/eval/association.h"
#include "arucoslam/exe/command_test_util.h"
#include "arucoslam/io/trajectory_io.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;
using testing_util::CommandResult;
using testing_util::RunArucoslam;

TEST(KittiKeypointSlam, First160FramesOfSequence07) {
  const fs::path sequence = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "kitti07_first160" / "euroc";
  if (!fs::exists(sequence / "mav0" / "cam0" / "data.csv")) {
    GTEST_SKIP() << "no KITTI data under " << sequence;
  }
  const fs::path out =
      fs::temp_directory_path() / ("arucoslam_kitti_test_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const CommandResult run = RunArucoslam("run --dataset " + sequence.string() + " --out " +
                                         out.string() + " --blocking --no-markers --quiet");
  ASSERT_EQ(run.status, 0) << run.output;

  const Trajectory gt =
      ReadEurocTrajectory(sequence / "mav0" / "state_groundtruth_estimate0" / "data.csv");
  const Trajectory est = ReadTumTrajectory(out / "trajectory.tum");
  ASSERT_EQ(gt.size(), 160u);
  const AssociatedTrajectories pairs = AssociateByTime(gt, est, {0.005});
  ASSERT_EQ(pairs.size(), est.size());
  const double posed = static_cast<double>(pairs.size()) / gt.size();
  AlignmentOptions align;
  align.mode = AlignmentMode::kSim3;
  const std::optional<AlignmentResult> alignment = ComputeAlignment(pairs, align);
  ASSERT_TRUE(alignment);
  const Trajectory aligned = ApplyAlignment(alignment->gt_from_est, pairs.est);
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    sum_sq += (aligned.poses[i].translation - pairs.gt.poses[i].translation).squaredNorm();
  }
  const double ate = std::sqrt(sum_sq / pairs.size());
  std::printf("posed %.1f%% of 160 frames, Sim3 ATE %.4f m\n", 100.0 * posed, ate);
  // The blocking run measured 0.46 m with 99.4% of the frames (BENCHMARKS.md, "Keypoint SLAM
  // on KITTI 07"); before the initialiser judged the plane's twin motion it was 1.22 m.
  EXPECT_GE(posed, 0.97);
  EXPECT_LE(ate, 0.60);
  fs::remove_all(out);
}

}  // namespace
}  // namespace arucoslam
