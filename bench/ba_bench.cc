// Bundle-adjustment timings: a local window of 10 keyframes and 1000 points (Ceres), and the
// pose-only optimisation tracking runs on every frame.
#include <benchmark/benchmark.h>

#include <random>

#include "arucoslam/optim/bundle_adjustment.h"
#include "arucoslam/optim/pose_optimizer.h"
#include "arucoslam/optim/synthetic_scene.h"

namespace arucoslam {
namespace {

// The synthetic window with every pose but the first two perturbed by ~2 cm / 1 degree and
// every point by ~10 cm.
BundleAdjustmentProblem PerturbedWindow(int num_poses, int num_points) {
  SyntheticSceneOptions options;
  options.num_poses = num_poses;
  options.num_points = num_points;
  options.noise_px = 0.5;
  BundleAdjustmentProblem problem = MakeSyntheticScene(options);
  std::mt19937 random(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (std::size_t i = 0; i < problem.poses.size(); ++i) {
    if (i < 2) {
      problem.poses[i].fixed = true;
      continue;
    }
    Vector6d delta;
    for (int k = 0; k < 6; ++k) delta[k] = 0.02 * normal(random);
    problem.poses[i].cam_from_world = Rigid3::Exp(delta) * problem.poses[i].cam_from_world;
  }
  for (auto& point : problem.points) {
    point.p_in_world += 0.1 * Eigen::Vector3d(normal(random), normal(random), normal(random));
  }
  return problem;
}

void BM_LocalBundleAdjustment(benchmark::State& state) {
  const BundleAdjustmentProblem start =
      PerturbedWindow(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  BundleAdjustmentOptions options;
  options.max_iterations = 10;  // what local mapping runs per keyframe
  BundleAdjustmentSummary summary;
  for (auto _ : state) {
    BundleAdjustmentProblem problem = start;
    summary = SolveBundleAdjustment(options, &problem);
    benchmark::DoNotOptimize(problem.poses.data());
  }
  state.counters["residuals"] = summary.num_residual_blocks;
  state.counters["iterations"] = summary.num_iterations;
  state.counters["final_rms_px"] = summary.final_rms_px;
}
BENCHMARK(BM_LocalBundleAdjustment)
    ->Args({10, 1000})
    ->Args({20, 2000})
    ->Unit(benchmark::kMillisecond);

void BM_PoseOptimization(benchmark::State& state) {
  const BundleAdjustmentProblem scene = PerturbedWindow(3, static_cast<int>(state.range(0)));
  // Pose 2 against the true points, from its perturbed pose.
  SyntheticSceneOptions options;
  options.num_poses = 3;
  options.num_points = static_cast<int>(state.range(0));
  options.noise_px = 0.5;
  const BundleAdjustmentProblem truth = MakeSyntheticScene(options);
  std::vector<PoseObservation> observations;
  for (const auto& observation : truth.observations) {
    if (observation.pose_index != 2) continue;
    observations.push_back(
        {truth.points[observation.point_index].p_in_world, observation.pixel, 1.0});
  }
  PoseOptimizationResult result;
  for (auto _ : state) {
    result = OptimizePose(observations, scene.poses[2].cam_from_world, truth.intrinsics);
    benchmark::DoNotOptimize(result.cam_from_world);
  }
  state.counters["observations"] = static_cast<double>(observations.size());
  state.counters["inliers"] = result.num_inliers;
}
BENCHMARK(BM_PoseOptimization)->Arg(300)->Arg(1000)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
