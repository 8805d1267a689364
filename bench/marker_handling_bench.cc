// Marker handling per frame on a real sequence, as the System's tracking thread does it:
// detection plus camera location in the known marker map. CPU time per frame (median and
// mean), so a loaded machine does not inflate it. The sequence (EuRoC layout with a
// markers.json) is named by ARUCOSLAM_BENCH_SEQUENCE; the benchmark is skipped without it.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/markers/detector.h"

namespace arucoslam {
namespace {

double ThreadCpuMilliseconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return 1e3 * static_cast<double>(now.tv_sec) + 1e-6 * static_cast<double>(now.tv_nsec);
}

// Every `stride`-th frame of the sequence, up to `count` images.
void BM_MarkerHandlingPerFrame(benchmark::State& state) {
  const char* root = std::getenv("ARUCOSLAM_BENCH_SEQUENCE");
  if (root == nullptr || !std::filesystem::exists(root)) {
    state.SkipWithError("set ARUCOSLAM_BENCH_SEQUENCE to a sequence with a markers.json");
    return;
  }
  const Dataset dataset = Dataset::Open(root);
  if (!dataset.markers_path()) {
    state.SkipWithError("the sequence has no markers.json");
    return;
  }
  const MarkerMap known = ReadMarkerMapJson(*dataset.markers_path());
  DetectorOptions detector_options;
  detector_options.dictionary = known.dictionary;
  const MarkerDetector detector(detector_options);
  const std::size_t stride = static_cast<std::size_t>(state.range(0));
  std::vector<cv::Mat> images;
  for (std::size_t i = 0; i < dataset.size() && images.size() < 400; i += stride) {
    images.push_back(dataset.LoadImage(i));
  }
  std::vector<double> per_frame;
  int with_markers = 0;
  for (auto _ : state) {
    per_frame.clear();
    with_markers = 0;
    for (const cv::Mat& image : images) {
      const double start = ThreadCpuMilliseconds();
      const std::vector<MarkerDetection> detections = detector.Detect(image);
      const CameraLocation location = LocateCamera(detections, known, dataset.camera());
      per_frame.push_back(ThreadCpuMilliseconds() - start);
      with_markers += detections.empty() ? 0 : 1;
      benchmark::DoNotOptimize(location.found);
    }
  }
  std::vector<double> sorted = per_frame;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  state.counters["frames"] = static_cast<double>(images.size());
  state.counters["frames_with_markers"] = with_markers;
  state.counters["median_cpu_ms"] = sorted[sorted.size() / 2];
  double sum = 0.0;
  for (double ms : per_frame) sum += ms;
  state.counters["mean_cpu_ms"] = sum / per_frame.size();
}
BENCHMARK(BM_MarkerHandlingPerFrame)->Arg(4)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
