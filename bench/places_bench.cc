// Place recognition as the running System uses it (pipeline/place_recognition.h): loading the
// shipped vocabulary, and the keyframe that closes a loop, from its database insertion and
// detection to the corrected map, on the synthetic wall route.
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <mutex>

#include "arucoslam/pipeline/place_recognition.h"
#include "arucoslam/slam/synthetic_route_map.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

const fs::path kVocabulary =
    fs::path(ARUCOSLAM_SOURCE_DIR) / "data" / "vocabulary" / "orb_k10_l5.bin";

std::shared_ptr<const Vocabulary> ShippedVocabulary() {
  static const std::shared_ptr<const Vocabulary> vocabulary =
      std::make_shared<const Vocabulary>(Vocabulary::Load(kVocabulary));
  return vocabulary;
}

void BM_LoadVocabulary(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(Vocabulary::Load(kVocabulary));
  state.counters["MB"] = static_cast<double>(fs::file_size(kVocabulary)) / 1e6;
}
BENCHMARK(BM_LoadVocabulary)->Unit(benchmark::kMillisecond);

// The synthetic wall route (slam/synthetic_route_map.h): a keyframe every 8.5 degrees over
// 450 degrees, so that the second lap revisits the first. Keyframes are mapped in order
// (database, detection with the 3-keyframe consistency check, closing, no global BA).
// Time: the one KeyframeMapped call that closed the loop, from its database insertion to
// the corrected map (manual time; the other keyframes are not counted).
void BM_DetectionToCorrectedMap(benchmark::State& state) {
  double detection_ms = 0.0, correction_ms = 0.0;
  for (auto _ : state) {
    SyntheticRoute route;
    Map map;
    std::vector<Rigid3> poses;
    for (double azimuth = 0.0; azimuth <= 450.0 + 1e-9; azimuth += 8.5) {
      poses.push_back(route.CamFromWorld(azimuth));
    }
    const std::vector<KeyframeId> keyframes = route.AddRoute(poses, &map);
    PlaceRecognitionOptions options;
    options.global_bundle_adjustment = false;
    PlaceRecognitionStats stats;
    std::mutex stats_mutex;
    PlaceRecognition places(map, ShippedVocabulary(), options, false, &stats, &stats_mutex);
    double closing_s = -1.0;
    for (const KeyframeId& keyframe : keyframes) {
      const auto start = std::chrono::steady_clock::now();
      places.KeyframeMapped(keyframe);
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!stats.loops.empty()) {
        closing_s = elapsed;
        correction_ms = stats.loops.front().detection_to_corrected_ms;
        detection_ms = stats.loop_detection_ms.Summarize().median;
        break;
      }
    }
    if (closing_s < 0.0) {
      state.SkipWithError("loop not closed");
      break;
    }
    state.SetIterationTime(closing_s);
  }
  state.counters["detection_median_ms"] = detection_ms;
  state.counters["closing_ms"] = correction_ms;
}
BENCHMARK(BM_DetectionToCorrectedMap)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
