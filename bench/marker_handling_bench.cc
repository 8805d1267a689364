// Marker handling per frame on a real sequence, as System::ProcessImage does it: detection
// on a worker thread while the calling thread extracts ORB features, then camera location
// in the known marker map. Consecutive frames from the start of the sequence (up to 900);
// the argument is MarkerSearchOptions::full_scan_interval (1: the whole image every frame;
// 15: the default, regions around the markers expected from the previous frame's pose,
// taken here from the ground truth where the System uses its own estimate). Per frame
// (median and mean):
//  - critical_ms: what the frame waits for markers, wall time from extraction's end until
//    the detections are ready, plus location (the figure issue 7 bounds);
//  - cpu_ms: CPU time of detection + location, all threads of the process (OpenCV's
//    detectMarkers uses its own thread pool), measured without extraction running;
//  - extraction_ms: the ORB extraction it overlaps with.
// The sequence (EuRoC layout with a markers.json and ground truth) is named by
// ARUCOSLAM_BENCH_SEQUENCE; the benchmark is skipped without it.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "arucoslam/feature/orb_extractor.h"
#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/detector_regions.h"
#include "arucoslam/pipeline/marker_detector_worker.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {
namespace {

// The ground-truth cam_from_world nearest in time to `timestamp_s`.
Rigid3 TruePose(const Trajectory& truth, double timestamp_s) {
  const auto it = std::lower_bound(truth.timestamps.begin(), truth.timestamps.end(), timestamp_s);
  std::size_t index = static_cast<std::size_t>(it - truth.timestamps.begin());
  if (index == truth.size() ||
      (index > 0 && timestamp_s - truth.timestamps[index - 1] < truth.timestamps[index] - timestamp_s)) {
    --index;
  }
  return truth.poses[index].Inverse();
}

void BM_MarkerHandlingPerFrame(benchmark::State& state) {
  const char* root = std::getenv("ARUCOSLAM_BENCH_SEQUENCE");
  if (root == nullptr || !std::filesystem::exists(root)) {
    state.SkipWithError("set ARUCOSLAM_BENCH_SEQUENCE to a sequence with a markers.json");
    return;
  }
  const Dataset dataset = Dataset::Open(root);
  if (!dataset.markers_path() || !dataset.has_ground_truth()) {
    state.SkipWithError("the sequence has no markers.json or no ground truth");
    return;
  }
  const MarkerMap known = ReadMarkerMapJson(*dataset.markers_path());
  SystemOptions system_options;  // the detector and extractor `arucoslam run` uses
  system_options.detector.dictionary = known.dictionary;
  system_options.marker_search.full_scan_interval = static_cast<int>(state.range(0));
  const MarkerDetector detector(system_options.detector);
  MarkerDetectorWorker worker(detector);
  const OrbExtractor extractor(system_options.extractor);
  const std::size_t count = std::min<std::size_t>(dataset.size(), 900);
  TimingStats critical, cpu, extraction;
  int with_markers = 0, full_scans = 0;
  for (auto _ : state) {
    // Pass 1 as ProcessImage: detection overlapping extraction. Pass 2: detection alone.
    for (const bool overlapped : {true, false}) {
      MarkerSearchPlanner planner(dataset.camera(), system_options.detector,
                                  system_options.marker_search);
      for (std::size_t i = 0; i < count; ++i) {
        state.PauseTiming();
        const cv::Mat image = dataset.LoadImage(i);
        state.ResumeTiming();
        const std::optional<std::vector<cv::Rect>> regions = planner.Next(known);
        std::vector<MarkerDetection> detections;
        if (overlapped) {
          const Stopwatch frame;
          worker.Start(image, regions);
          const OrbFeatures features = extractor.Extract(image);
          extraction.Add(frame.ElapsedMilliseconds());
          const Stopwatch waiting;
          detections = worker.Wait().detections;
          const CameraLocation location = LocateCamera(detections, known, dataset.camera());
          critical.Add(waiting.ElapsedMilliseconds());
          benchmark::DoNotOptimize(features.keypoints.size());
          benchmark::DoNotOptimize(location.found);
          with_markers += detections.empty() ? 0 : 1;
        } else {
          const double start = ProcessCpuMilliseconds();
          detections =
              regions ? detector.DetectInRegions(image, *regions) : detector.Detect(image);
          const CameraLocation location = LocateCamera(detections, known, dataset.camera());
          cpu.Add(ProcessCpuMilliseconds() - start);
          benchmark::DoNotOptimize(location.found);
        }
        planner.Remember(TruePose(dataset.ground_truth(), dataset.frame(i).timestamp_s),
                         detections);
      }
      if (!overlapped) full_scans = planner.num_full_scans();
    }
  }
  state.counters["frames"] = static_cast<double>(count);
  state.counters["frames_with_markers"] = with_markers;
  state.counters["full_scans"] = full_scans;
  const TimingSummary critical_ms = critical.Summarize(), cpu_ms = cpu.Summarize();
  state.counters["critical_median_ms"] = critical_ms.median;
  state.counters["critical_mean_ms"] = critical_ms.mean;
  state.counters["cpu_median_ms"] = cpu_ms.median;
  state.counters["cpu_mean_ms"] = cpu_ms.mean;
  state.counters["extraction_median_ms"] = extraction.Summarize().median;
}
BENCHMARK(BM_MarkerHandlingPerFrame)
    ->Arg(1)
    ->Arg(15)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
