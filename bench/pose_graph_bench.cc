// Loop-closing timings: the Sim3 pose graph of a drifted loop (40 to 1000 keyframes, Ceres),
// the Sim3 RANSAC solver, a whole loop closure (detection to corrected map) and the global BA.
#include <benchmark/benchmark.h>

#include <random>

#include "arucoslam/geometry/sim3_solver.h"
#include "arucoslam/optim/global_bundle_adjustment.h"
#include "arucoslam/optim/pose_graph.h"
#include "arucoslam/optim/synthetic_loop.h"
#include "arucoslam/slam/loop_closer.h"
#include "arucoslam/slam/synthetic_loop_map.h"

namespace arucoslam {
namespace {

void BM_PoseGraphLoop(benchmark::State& state) {
  SyntheticLoopOptions options;
  options.num_keyframes = static_cast<int>(state.range(0));
  // The same total drift (about 0.4 rad, 1.5x) whatever the number of keyframes.
  options.yaw_drift_rad = 0.4 / options.num_keyframes;
  options.scale_drift = std::pow(1.5, 1.0 / options.num_keyframes);
  const SyntheticLoop loop = MakeSyntheticLoop(options);
  double rms = 0.0;
  for (auto _ : state) {
    PoseGraphProblem problem = loop.problem;
    const PoseGraphSummary summary = SolvePoseGraph({}, &problem);
    benchmark::DoNotOptimize(summary.final_cost);
    rms = CameraCentreRms(problem, loop.truth_cam_from_world);
  }
  state.counters["rms_after_m"] = rms;
  state.counters["rms_before_m"] = CameraCentreRms(loop.problem, loop.truth_cam_from_world);
}
BENCHMARK(BM_PoseGraphLoop)->Arg(40)->Arg(200)->Arg(1000)->Unit(benchmark::kMillisecond);

CameraModel BenchCamera() {
  return PinholeCamera(640, 480, 500.0);
}

std::vector<Sim3Correspondence> MakeMatches(const Sim3& candidate_from_current, int count) {
  const CameraModel camera = BenchCamera();
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 0.5);
  auto point = [&](double scale) -> Eigen::Vector3d {
    const double z = 2.0 + 4.0 * unit(random);
    return scale * Eigen::Vector3d((unit(random) - 0.5) * z, (unit(random) - 0.5) * z, z);
  };
  auto project = [&](const Eigen::Vector3d& p) -> Eigen::Vector2d {
    return {camera.fx * p.x() / p.z() + camera.cx + normal(random),
            camera.fy * p.y() / p.z() + camera.cy + normal(random)};
  };
  std::vector<Sim3Correspondence> matches;
  for (int i = 0; i < count; ++i) {
    Sim3Correspondence c;
    c.p_in_current = point(1.0);
    c.p_in_candidate = unit(random) < 0.4
                           ? point(candidate_from_current.scale)
                           : Eigen::Vector3d(candidate_from_current * c.p_in_current);
    c.pixel_in_current = project(c.p_in_current);
    c.pixel_in_candidate = project(c.p_in_candidate);
    matches.push_back(c);
  }
  return matches;
}

void BM_Sim3Solver(benchmark::State& state) {
  const Sim3 truth(1.5, Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY())),
                   Eigen::Vector3d(0.3, 0.0, 0.2));
  const auto matches = MakeMatches(truth, static_cast<int>(state.range(0)));
  int inliers = 0;
  for (auto _ : state) {
    const Sim3SolverResult result = SolveSim3(BenchCamera(), BenchCamera(), matches);
    inliers = result.num_inliers;
    benchmark::DoNotOptimize(result.candidate_from_current);
  }
  state.counters["inliers"] = inliers;
}
BENCHMARK(BM_Sim3Solver)->Arg(100)->Arg(300)->Unit(benchmark::kMillisecond);

// From a verified candidate to the corrected map: matching, Sim3, fusion, essential graph
// (40 keyframes, ~3000 points, the drifted wall loop of slam/synthetic_loop_map.h).
void BM_LoopClosure(benchmark::State& state) {
  double rms_after = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    Map map;
    const SyntheticLoopMap scene = BuildSyntheticLoopMap({}, &map);
    LoopCloser closer(map);
    state.ResumeTiming();
    const LoopClosureResult result = closer.CloseLoop(scene.keyframes.back(), scene.keyframes[0]);
    state.PauseTiming();
    if (!result.closed) state.SkipWithError(result.reason.c_str());
    rms_after = KeyframeCentreRms(map, scene);
    state.ResumeTiming();
  }
  state.counters["rms_after_m"] = rms_after;
}
BENCHMARK(BM_LoopClosure)->Unit(benchmark::kMillisecond);

// The global bundle adjustment that follows (snapshot, solve, write-back) on the closed map.
void BM_GlobalBundleAdjustment(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    Map map;
    const SyntheticLoopMap scene = BuildSyntheticLoopMap({}, &map);
    LoopCloser(map).CloseLoop(scene.keyframes.back(), scene.keyframes[0]);
    state.ResumeTiming();
    const GlobalBundleAdjustmentResult result = RunGlobalBundleAdjustment(map);
    state.counters["points"] = result.num_points;
    state.counters["iterations"] = result.summary.num_iterations;
    state.PauseTiming();
    state.counters["rms_after_m"] = KeyframeCentreRms(map, scene);
    state.ResumeTiming();
  }
}
BENCHMARK(BM_GlobalBundleAdjustment)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
