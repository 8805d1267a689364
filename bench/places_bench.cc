// Place recognition as the running System uses it (pipeline/place_recognition.h): loading the
// shipped vocabulary, one mapped keyframe through database + loop detection, and a keyframe
// that closes the loop, from detection to the corrected map, on the synthetic drifted loop.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <mutex>

#include "arucoslam/pipeline/place_recognition.h"
#include "arucoslam/slam/synthetic_loop_map.h"

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

// The synthetic loop (40 keyframes, ~3000 points, drifted) with every keyframe but the last
// in the database; the last one closes the loop when it is mapped.
struct LoopScene {
  Map map;
  SyntheticLoopMap scene;
  PlaceRecognitionStats stats;
  std::mutex stats_mutex;
  std::unique_ptr<PlaceRecognition> places;

  explicit LoopScene(bool loop_closing) {
    scene = BuildSyntheticLoopMap({}, &map);
    PlaceRecognitionOptions options;
    options.loop_closing = false;  // while the database is filled
    options.global_bundle_adjustment = false;
    options.detector.min_consistent_keyframes = 1;
    places = std::make_unique<PlaceRecognition>(map, ShippedVocabulary(), options, false, &stats,
                                                 &stats_mutex);
    for (std::size_t i = 0; i + 1 < scene.keyframes.size(); ++i) {
      places->KeyframeMapped(scene.keyframes[i]);
    }
    places->SetLoopClosing(loop_closing);
  }
};

// Database insertion + loop query of one keyframe (loop closing off: no correction).
void BM_KeyframeDatabaseAndDetection(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    LoopScene loop(false);
    state.ResumeTiming();
    loop.places->KeyframeMapped(loop.scene.keyframes.back());
  }
}
BENCHMARK(BM_KeyframeDatabaseAndDetection)->Unit(benchmark::kMillisecond);

// Database, detection, Sim3, fusion and essential graph: the new keyframe to the corrected map.
void BM_DetectionToCorrectedMap(benchmark::State& state) {
  double rms_before = 0.0, rms_after = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    LoopScene loop(true);
    rms_before = KeyframeCentreRms(loop.map, loop.scene);
    state.ResumeTiming();
    loop.places->KeyframeMapped(loop.scene.keyframes.back());
    state.PauseTiming();
    if (loop.stats.loops.size() != 1) state.SkipWithError("loop not closed");
    rms_after = KeyframeCentreRms(loop.map, loop.scene);
    state.ResumeTiming();
  }
  state.counters["rms_before_m"] = rms_before;
  state.counters["rms_after_m"] = rms_after;
}
BENCHMARK(BM_DetectionToCorrectedMap)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
