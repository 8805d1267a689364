// Acceptance on a short render: keypoint-only SLAM (`run --no-markers`) on a
// medium-texture factory whose first corner is made a tight turn (0.9 m radius); up to that
// turn it must initialise within 2 s, pose >= 95% of the frames from initialisation on (on a
// 10 s render the 2 s allowed for initialisation alone would be 20%), Sim(3) ATE <= 2% of
// the distance travelled.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "arucoslam/eval/alignment.h"
#include "arucoslam/eval/association.h"
#include "arucoslam/exe/command_test_util.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;
using testing_util::CommandResult;
using testing_util::RunArucoslam;

// Heading (radians) of the ground-truth motion from pose i to pose i + step.
double Heading(const Trajectory& gt, std::size_t i, std::size_t step) {
  const Eigen::Vector3d d = gt.poses[i + step].translation - gt.poses[i].translation;
  return std::atan2(d.y(), d.x());
}

// Time (seconds after the first pose) when the route has turned by `angle` radians from its
// initial heading: the start of the first turn.
double FirstTurnStart(const Trajectory& gt, double angle) {
  const std::size_t step = 15;  // 0.5 s at 30 Hz: smooths the camera's vibration
  const double initial = Heading(gt, 30, step);
  for (std::size_t i = 30; i + step < gt.size(); ++i) {
    const double turned = std::remainder(Heading(gt, i, step) - initial, 2.0 * M_PI);
    if (std::abs(turned) > angle) return gt.timestamps[i] - gt.timestamps[0];
  }
  return gt.timestamps.back() - gt.timestamps[0];
}

TEST(KeypointSlamAcceptance, MediumTextureTracksUpToTheTightTurn) {
  const ScratchFolder scratch("acceptance_test");
  const fs::path& dir = scratch.path();
  const CommandResult world =
      RunArucoslam("world factory --seed 1 --texture medium --markers off --aisles 1 "
                   "--aisle-length 6 --out " + (dir / "world").string());
  ASSERT_EQ(world.status, 0) << world.output;
  // The default route of this short hall; its first corner (after 7.6 m) gets the tightest
  // radius of the default route, 0.9 m.
  nlohmann::json path;
  std::ifstream(dir / "world" / "path.json") >> path;
  path["waypoints"][1]["turn_radius_m"] = 0.9;
  std::ofstream(dir / "tight_path.json") << path.dump(2);
  const CommandResult render = RunArucoslam(
      "simulate --world " + (dir / "world" / "world.sdf").string() + " --path " +
      (dir / "tight_path.json").string() + " --out " + (dir / "seq").string() +
      " --max-seconds 10 --quiet");
  ASSERT_EQ(render.status, 0) << render.output;
  const CommandResult run = RunArucoslam("run --dataset " + (dir / "seq").string() + " --out " +
                                         (dir / "run").string() +
                                         " --blocking --no-markers --quiet");
  ASSERT_EQ(run.status, 0) << run.output;

  const Trajectory gt =
      ReadEurocTrajectory(dir / "seq" / "mav0" / "state_groundtruth_estimate0" / "data.csv");
  const Trajectory est = ReadTumTrajectory(dir / "run" / "trajectory.tum");
  ASSERT_GE(gt.size(), 290u);
  ASSERT_GE(est.size(), 2u);
  const double t0 = gt.timestamps.front();
  const double turn = FirstTurnStart(gt, 0.2);
  // The turn must lie inside the render, after the straight aisle.
  ASSERT_GT(turn, 6.0);
  ASSERT_LT(turn, 9.9);

  // The first pose is the initialisation reference, the second the frame completing it.
  const double init_s = est.timestamps[1] - t0;
  EXPECT_LE(init_s, 2.0);

  Trajectory before_turn;
  std::size_t tracked_after_init = 0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    if (est.timestamps[i] - t0 > turn) continue;
    before_turn.AddFrom(est, i);
    tracked_after_init += i >= 1 ? 1 : 0;
  }
  std::size_t gt_frames = 0;
  for (double t : gt.timestamps) gt_frames += t - t0 >= init_s - 1e-6 && t - t0 <= turn ? 1 : 0;
  const double tracked = static_cast<double>(tracked_after_init) / gt_frames;
  EXPECT_GE(tracked, 0.95);

  const AssociatedTrajectories pairs = AssociateByTime(gt, before_turn, {0.005});
  ASSERT_EQ(pairs.size(), before_turn.size());
  AlignmentOptions align;
  align.mode = AlignmentMode::kSim3;
  const std::optional<AlignmentResult> alignment = ComputeAlignment(pairs, align);
  ASSERT_TRUE(alignment);
  const Trajectory aligned = ApplyAlignment(alignment->gt_from_est, pairs.est);
  double sum_sq = 0.0;
  double distance = 0.0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    sum_sq += (aligned.poses[i].translation - pairs.gt.poses[i].translation).squaredNorm();
    if (i > 0) {
      distance += (pairs.gt.poses[i].translation - pairs.gt.poses[i - 1].translation).norm();
    }
  }
  const double ate = std::sqrt(sum_sq / pairs.size());
  EXPECT_GT(distance, 5.0);
  EXPECT_LE(ate, 0.02 * distance);
  std::printf("init %.2f s, tracked %.1f%% of the %zu frames from then to the turn at %.2f s, "
              "Sim3 ATE %.4f m over %.2f m (%.2f%%)\n",
              init_s, 100.0 * tracked, gt_frames, turn, ate, distance, 100.0 * ate / distance);
}

}  // namespace
}  // namespace arucoslam
