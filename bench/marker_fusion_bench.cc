// Marker-fusion timings: the marker-corner residual, pose-only optimisation of one frame with
// and without markers, marker bundle adjustment, and the online marker mapper.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>

#include "arucoslam/optim/marker_bundle_adjustment.h"
#include "arucoslam/optim/marker_bundle_adjustment_synthetic.h"
#include "arucoslam/optim/marker_corner_error.h"
#include "arucoslam/optim/marker_pose_optimizer.h"
#include "arucoslam/optim/pose_optimizer.h"

namespace arucoslam {
namespace {

SyntheticMarkerSceneOptions NoisyScene() {
  SyntheticMarkerSceneOptions options;
  options.noise_px = 0.5;
  options.corner_noise_px = 0.3;
  options.num_points = 1000;
  return options;
}

const MarkerBundleAdjustmentProblem& Scene() {
  static const MarkerBundleAdjustmentProblem scene = MakeSyntheticMarkerScene(NoisyScene());
  return scene;
}

void BM_MarkerCornerError(benchmark::State& state) {
  const bool jacobians = state.range(0) != 0;
  const MarkerBundleAdjustmentProblem& scene = Scene();
  const auto& observation = scene.marker_observations.front();
  const auto& marker = scene.markers[observation.marker_index];
  const double h = marker.size / 2;
  const MarkerCornerError error(scene.keypoints.intrinsics,
                                {Eigen::Vector3d(-h, h, 0), Eigen::Vector3d(h, h, 0),
                                 Eigen::Vector3d(h, -h, 0), Eigen::Vector3d(-h, -h, 0)},
                                observation.corners_px);
  const Rigid3& cam_from_world = scene.keypoints.poses[observation.pose_index].cam_from_world;
  Vector8d residual;
  MarkerCornerJacobian d_cam, d_marker;
  for (auto _ : state) {
    benchmark::DoNotOptimize(error.Evaluate(cam_from_world, marker.world_from_marker, &residual,
                                            jacobians ? &d_cam : nullptr,
                                            jacobians ? &d_marker : nullptr));
    benchmark::DoNotOptimize(residual);
  }
}
BENCHMARK(BM_MarkerCornerError)->Arg(0)->Arg(1)->ArgNames({"jacobians"});

// The pose of the scene that sees the most markers.
std::size_t BusiestPose(const MarkerBundleAdjustmentProblem& scene) {
  std::vector<int> counts(scene.keypoints.poses.size(), 0);
  for (const auto& observation : scene.marker_observations) ++counts[observation.pose_index];
  return std::max_element(counts.begin(), counts.end()) - counts.begin();
}

// That frame started 5 cm / 1 degree off; range(0) = 1 adds its markers to the keypoints.
void BM_PoseOnlyOptimization(benchmark::State& state) {
  const bool with_markers = state.range(0) != 0;
  const MarkerBundleAdjustmentProblem& scene = Scene();
  const std::size_t pose = BusiestPose(scene);
  std::vector<PoseObservation> keypoints;
  for (const auto& observation : scene.keypoints.observations) {
    if (observation.pose_index != pose) continue;
    keypoints.push_back(
        {scene.keypoints.points[observation.point_index].p_in_world, observation.pixel, 1.0});
  }
  std::vector<MarkerPoseObservation> markers;
  for (const auto& observation : scene.marker_observations) {
    if (observation.pose_index != pose || !with_markers) continue;
    const auto& marker = scene.markers[observation.marker_index];
    markers.push_back({marker.world_from_marker, marker.size, observation.corners_px, 1.0});
  }
  Vector6d delta;
  delta << 0.05, -0.03, 0.02, 0.015, -0.01, 0.005;
  const Rigid3 start = Rigid3::Exp(delta) * scene.keypoints.poses[pose].cam_from_world;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        OptimizePoseWithMarkers(keypoints, markers, start, scene.keypoints.intrinsics));
  }
  state.counters["keypoints"] = static_cast<double>(keypoints.size());
  state.counters["markers"] = static_cast<double>(markers.size());
}
BENCHMARK(BM_PoseOnlyOptimization)
    ->Arg(0)
    ->Arg(1)
    ->ArgNames({"markers"})
    ->Unit(benchmark::kMicrosecond);

// Keypoints-only OptimizePose on the same frame, for comparison with the above.
void BM_PoseOnlyOptimizationBaseline(benchmark::State& state) {
  const MarkerBundleAdjustmentProblem& scene = Scene();
  const std::size_t pose = BusiestPose(scene);
  std::vector<PoseObservation> keypoints;
  for (const auto& observation : scene.keypoints.observations) {
    if (observation.pose_index != pose) continue;
    keypoints.push_back(
        {scene.keypoints.points[observation.point_index].p_in_world, observation.pixel, 1.0});
  }
  Vector6d delta;
  delta << 0.05, -0.03, 0.02, 0.015, -0.01, 0.005;
  const Rigid3 start = Rigid3::Exp(delta) * scene.keypoints.poses[pose].cam_from_world;
  for (auto _ : state) {
    benchmark::DoNotOptimize(OptimizePose(keypoints, start, scene.keypoints.intrinsics));
  }
}
BENCHMARK(BM_PoseOnlyOptimizationBaseline)->Unit(benchmark::kMicrosecond);

// Whole-scene bundle adjustment (20 keyframes, ~1000 points, 4 markers, one known) from a
// start 3% off in scale with 3 mm drift per pose.
void BM_MarkerBundleAdjustment(benchmark::State& state) {
  MarkerBundleAdjustmentProblem start = Scene();
  std::mt19937 random(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (auto& pose : start.keypoints.poses) {
    Rigid3 world_from_cam = pose.cam_from_world.Inverse();
    world_from_cam.translation *= 1.03;
    Vector6d delta;
    for (int k = 0; k < 6; ++k) delta[k] = 0.003 * normal(random);
    pose.cam_from_world = Rigid3::Exp(delta) * world_from_cam.Inverse();
  }
  for (auto& point : start.keypoints.points) point.p_in_world *= 1.03;
  for (std::size_t m = 1; m < start.markers.size(); ++m) start.markers[m].fixed = false;
  for (auto _ : state) {
    MarkerBundleAdjustmentProblem problem = start;
    benchmark::DoNotOptimize(SolveMarkerBundleAdjustment({}, &problem));
  }
}
BENCHMARK(BM_MarkerBundleAdjustment)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
