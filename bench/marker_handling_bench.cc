// Marker handling per frame on a real sequence, as System::ProcessImage does it: detection
// on a worker thread while the calling thread extracts ORB features, then camera location
// in the known marker map. Reports per frame (median and mean):
//  - critical_ms: what the frame waits for markers, wall time from extraction's end until
//    the detections are ready, plus location (the figure issue 7 bounds);
//  - cpu_ms: CPU time of detection + location, all threads of the process (OpenCV's
//    detectMarkers uses its own thread pool), measured in a separate pass without extraction;
//  - extraction_ms: the ORB extraction it overlaps with.
// The sequence (EuRoC layout with a markers.json) is named by ARUCOSLAM_BENCH_SEQUENCE; the
// benchmark is skipped without it.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "arucoslam/feature/orb_extractor.h"
#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/detector_worker.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {
namespace {

double ProcessCpuMilliseconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return 1e3 * static_cast<double>(now.tv_sec) + 1e-6 * static_cast<double>(now.tv_nsec);
}

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

double Mean(const std::vector<double>& values) {
  double sum = 0.0;
  for (double value : values) sum += value;
  return sum / static_cast<double>(values.size());
}

// Every `stride`-th frame of the sequence, up to 400 images.
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
  SystemOptions system_options;  // the detector and extractor `arucoslam run` uses
  system_options.detector.dictionary = known.dictionary;
  const MarkerDetector detector(system_options.detector);
  MarkerDetectorWorker worker(detector);
  const OrbExtractor extractor(system_options.extractor);
  const std::size_t stride = static_cast<std::size_t>(state.range(0));
  std::vector<cv::Mat> images;
  for (std::size_t i = 0; i < dataset.size() && images.size() < 400; i += stride) {
    images.push_back(dataset.LoadImage(i));
  }
  std::vector<double> critical, cpu, extraction;
  int with_markers = 0;
  for (auto _ : state) {
    critical.clear();
    cpu.clear();
    extraction.clear();
    with_markers = 0;
    for (const cv::Mat& image : images) {
      const Stopwatch frame;
      worker.Start(image);
      const OrbFeatures features = extractor.Extract(image);
      extraction.push_back(frame.ElapsedMilliseconds());
      const Stopwatch waiting;
      const TimedDetections detected = worker.Wait();
      const CameraLocation location = LocateCamera(detected.detections, known, dataset.camera());
      critical.push_back(waiting.ElapsedMilliseconds());
      with_markers += detected.detections.empty() ? 0 : 1;
      benchmark::DoNotOptimize(features.keypoints.size());
      benchmark::DoNotOptimize(location.found);
    }
    for (const cv::Mat& image : images) {
      const double start = ProcessCpuMilliseconds();
      const std::vector<MarkerDetection> detections = detector.Detect(image);
      const CameraLocation location = LocateCamera(detections, known, dataset.camera());
      cpu.push_back(ProcessCpuMilliseconds() - start);
      benchmark::DoNotOptimize(location.found);
    }
  }
  state.counters["frames"] = static_cast<double>(images.size());
  state.counters["frames_with_markers"] = with_markers;
  state.counters["critical_median_ms"] = Median(critical);
  state.counters["critical_mean_ms"] = Mean(critical);
  state.counters["cpu_median_ms"] = Median(cpu);
  state.counters["cpu_mean_ms"] = Mean(cpu);
  state.counters["extraction_median_ms"] = Median(extraction);
}
BENCHMARK(BM_MarkerHandlingPerFrame)->Arg(4)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
