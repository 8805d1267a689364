// Tracking and local-mapping timings of the SLAM pipeline: per-frame tracking (median, p95),
// local mapping per keyframe, wall time and peak memory of a blocking run, on a synthetic
// feature sequence and on an image sequence (ARUCOSLAM_BENCH_SEQUENCE, default the real
// EuRoC clip, where the camera is static and only extraction + initialisation attempts run).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/slam/synthetic_features.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {
namespace {

void ReportStats(benchmark::State& state, const SystemStats& stats, double wall_s) {
  const TimingSummary tracking = stats.tracking_ms.Summarize();
  const TimingSummary mapping = stats.local_mapping_ms.Summarize();
  const TimingSummary extraction = stats.extraction_ms.Summarize();
  state.counters["track_median_ms"] = tracking.median;
  state.counters["track_p95_ms"] = tracking.p95;
  state.counters["extract_median_ms"] = extraction.median;
  state.counters["mapping_median_ms"] = mapping.median;
  state.counters["mapping_p95_ms"] = mapping.p95;
  state.counters["keyframes"] = static_cast<double>(stats.num_keyframes_inserted);
  state.counters["tracked"] = stats.num_tracked;
  state.counters["frames"] = stats.num_frames;
  state.counters["wall_s"] = wall_s;
  state.counters["peak_MiB"] = PeakMemoryBytes() / (1024.0 * 1024.0);
}

// 120 frames of synthetic features (about 1000 keypoints each, 640x480, 20 Hz) along a
// sideways path; tracking and mapping only (no image processing).
void BM_BlockingSyntheticRun(benchmark::State& state) {
  const CameraModel camera = PinholeCamera(640, 480, 500.0);
  SyntheticFeatureOptions scene_options;
  scene_options.num_points = 2000;
  for (auto _ : state) {
    SyntheticFeatureScene scene(camera, scene_options);
    const Stopwatch wall;
    System system(camera);
    std::vector<int> truth;
    for (int t = 0; t < 120; ++t) {
      const Rigid3 world_from_cam(
          Eigen::Quaterniond(Eigen::AngleAxisd(0.003 * t, Eigen::Vector3d::UnitY())),
          Eigen::Vector3d(0.03 * t, 0.2 * std::sin(t / 15.0), 0.003 * t));
      system.ProcessFrame(scene.MakeFrame(FrameId(t), 0.05 * t, world_from_cam.Inverse(), &truth));
    }
    system.Finish();
    ReportStats(state, system.Stats(), wall.ElapsedSeconds());
  }
}
BENCHMARK(BM_BlockingSyntheticRun)->Unit(benchmark::kMillisecond)->Iterations(1);

// The whole pipeline on images: state.range(0) = 1 blocking, 0 threaded.
void BM_ImageSequenceRun(benchmark::State& state) {
  const char* env = std::getenv("ARUCOSLAM_BENCH_SEQUENCE");
  const std::filesystem::path root =
      env ? std::filesystem::path(env)
          : std::filesystem::path(ARUCOSLAM_TEST_DATA_DIR) / "euroc_v101_micro";
  if (!std::filesystem::exists(root)) {
    state.SkipWithError(("sequence missing: " + root.string()).c_str());
    return;
  }
  const Dataset dataset = Dataset::Open(root);
  SystemOptions options;
  options.blocking = state.range(0) == 1;
  for (auto _ : state) {
    const Stopwatch wall;
    System system(dataset.camera(), options);
    for (std::size_t i = 0; i < dataset.size(); ++i) {
      system.ProcessImage(dataset.LoadImage(i), dataset.frame(i).timestamp_s);
    }
    system.Finish();
    ReportStats(state, system.Stats(), wall.ElapsedSeconds());
  }
}
BENCHMARK(BM_ImageSequenceRun)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
