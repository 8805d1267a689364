// Relocalisation and loop-detection benchmarks on the synthetic wall route (slam/
// synthetic_route_map.h) with the shipped vocabulary: one lost frame relocalised against a
// mapped turn, a frame of an unmapped world rejected, and loop detection per keyframe.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <optional>

#include "arucoslam/slam/loop_detector.h"
#include "arucoslam/slam/relocalizer.h"
#include "arucoslam/slam/synthetic_route_map.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

const Vocabulary& ShippedVocabulary() {
  static const Vocabulary vocabulary =
      Vocabulary::Load(fs::path(ARUCOSLAM_SOURCE_DIR) / "data" / "vocabulary" / "orb_k10_l5.bin");
  return vocabulary;
}

// One turn of the route with a keyframe every `step_deg` degrees, its database filled.
struct MappedTurn {
  SyntheticRoute route;
  Map map;
  std::vector<KeyframeId> keyframes;
  KeyframeDatabase database{ShippedVocabulary()};

  explicit MappedTurn(double step_deg) {
    std::vector<Rigid3> poses;
    for (double azimuth = 0.0; azimuth < 360.0; azimuth += step_deg) {
      poses.push_back(route.CamFromWorld(azimuth));
    }
    keyframes = route.AddRoute(poses, &map);
    map.Read([&](const MapData& data) {
      for (const KeyframeId& id : keyframes) database.Add(*data.FindKeyframe(id));
      return 0;
    });
  }
};

// Relocalising a frame of a mapped place (40 keyframes, ~350 wall points and 150
// distractors in view).
void BM_RelocalizeLostFrame(benchmark::State& state) {
  MappedTurn turn(9.0);
  const Relocalizer relocalizer(turn.map, turn.database);
  std::vector<int> truth;
  const Frame frame =
      turn.route.MakeFrame(FrameId(1000), turn.route.CamFromWorld(130.5, 5.0, 0.3), 150, &truth);
  int inliers = 0;
  for (auto _ : state) {
    const std::optional<RelocalizationResult> result = relocalizer.Relocalize(frame);
    if (!result) state.SkipWithError("not relocalised");
    inliers = result ? result->num_inliers : 0;
  }
  state.counters["inliers"] = inliers;
}
BENCHMARK(BM_RelocalizeLostFrame)->Unit(benchmark::kMillisecond);

// Rejecting a frame of another world: the cost of a failed attempt while lost.
void BM_RelocalizeUnknownFrame(benchmark::State& state) {
  MappedTurn turn(9.0);
  const Relocalizer relocalizer(turn.map, turn.database);
  SyntheticRouteOptions other_options;
  other_options.seed = 77;
  SyntheticRoute other(other_options);
  std::vector<int> truth;
  const Frame frame = other.MakeFrame(FrameId(1), other.CamFromWorld(130.0), 150, &truth);
  for (auto _ : state) {
    if (relocalizer.Relocalize(frame)) state.SkipWithError("false relocalisation");
  }
}
BENCHMARK(BM_RelocalizeUnknownFrame)->Unit(benchmark::kMillisecond);

// Loop detection for one keyframe (reference score, database query excluding neighbours,
// grouping, consistency) in a database of 360 / step keyframes.
void BM_LoopDetectionPerKeyframe(benchmark::State& state) {
  const double step_deg = 360.0 / static_cast<double>(state.range(0));
  MappedTurn turn(step_deg);
  LoopDetector detector(turn.map, turn.database);
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(detector.DetectByWords(turn.keyframes[k]));
    k = (k + 1) % turn.keyframes.size();
  }
  state.counters["keyframes"] = static_cast<double>(turn.keyframes.size());
}
BENCHMARK(BM_LoopDetectionPerKeyframe)->Arg(40)->Arg(400)->Unit(benchmark::kMicrosecond);

// BoW vector and direct index of one keyframe (~500 descriptors) and its insertion.
void BM_KeyframeDatabaseAdd(benchmark::State& state) {
  MappedTurn turn(9.0);
  std::size_t k = 0;
  for (auto _ : state) {
    turn.map.Read([&](const MapData& data) {
      turn.database.Add(*data.FindKeyframe(turn.keyframes[k]));
      return 0;
    });
    k = (k + 1) % turn.keyframes.size();
  }
}
BENCHMARK(BM_KeyframeDatabaseAdd)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
