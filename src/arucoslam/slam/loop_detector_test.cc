#include "arucoslam/slam/loop_detector.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <optional>

#include "arucoslam/slam/loop_closer.h"
#include "arucoslam/slam/synthetic_route_map.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

const Vocabulary* DefaultVocabulary() {
  static const std::optional<Vocabulary> vocabulary = []() -> std::optional<Vocabulary> {
    const fs::path path = fs::path(ARUCOSLAM_SOURCE_DIR) / "data" / "vocabulary" / "orb_k10_l5.bin";
    if (!fs::exists(path)) return std::nullopt;
    return Vocabulary::Load(path);
  }();
  return vocabulary ? &*vocabulary : nullptr;
}

// Two views show the same place when they see at least this many wall points in common.
constexpr int kMinSharedForTrueLoop = 30;

// A route on the circle, a keyframe every 9 degrees up to `end_deg`, with markers 7 and 8
// on the wall at 30 and 200 degrees.
struct Route {
  SyntheticRoute route;
  Map map;
  std::vector<KeyframeId> keyframes;
  KeyframeDatabase database;

  Route(const Vocabulary& vocabulary, double end_deg, double step_deg = 9.0)
      : route([] {
          SyntheticRouteOptions options;
          options.markers = {{7, 30.0}, {8, 200.0}};
          return options;
        }()),
        database(vocabulary) {
    std::vector<Rigid3> poses;
    for (double azimuth = 0.0; azimuth <= end_deg + 1e-9; azimuth += step_deg) {
      poses.push_back(route.CamFromWorld(azimuth));
    }
    keyframes = route.AddRoute(poses, &map);
  }
  int IndexOf(KeyframeId id) const {
    return static_cast<int>(std::find(keyframes.begin(), keyframes.end(), id) - keyframes.begin());
  }
};

// The first keyframe that sees the place of an earlier keyframe it shares no map point with
// (at least kMinSharedForTrueLoop wall points in common), from the truth; -1 for none.
int FirstRevisit(Route& scene) {
  return scene.map.Read([&](const MapData& data) {
    for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
      for (std::size_t j = 0; j < i; ++j) {
        if (scene.route.SharedWallPoints(i, j) >= kMinSharedForTrueLoop &&
            data.covisibility().Weight(scene.keyframes[i], scene.keyframes[j]) == 0) {
          return static_cast<int>(i);
        }
      }
    }
    return -1;
  });
}

struct RunSummary {
  int first_word_detection = -1;  // index of the first keyframe with a BoW candidate
  int first_marker_detection = -1;
  int num_word_candidates = 0;
  int num_marker_candidates = 0;
  int num_false = 0;  // candidates that do not show the current keyframe's place
};

// Feeds the keyframes one by one (database insertion then detection), as mapping would.
RunSummary FeedRoute(Route& scene, const LoopDetectorOptions& options = {}) {
  LoopDetector detector(scene.map, scene.database, options);
  RunSummary summary;
  for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
    scene.map.Read([&](const MapData& data) {
      scene.database.Add(*data.FindKeyframe(scene.keyframes[i]));
      return 0;
    });
    const LoopCandidates candidates = detector.Detect(scene.keyframes[i]);
    auto count = [&](const std::vector<KeyframeId>& found, int* first, int* total) {
      if (!found.empty() && *first < 0) *first = static_cast<int>(i);
      *total += static_cast<int>(found.size());
      for (const KeyframeId& id : found) {
        if (scene.route.SharedWallPoints(i, scene.IndexOf(id)) < kMinSharedForTrueLoop) {
          ++summary.num_false;
        }
      }
    };
    count(candidates.by_words, &summary.first_word_detection, &summary.num_word_candidates);
    count(candidates.by_markers, &summary.first_marker_detection, &summary.num_marker_candidates);
  }
  return summary;
}

TEST(LoopDetectorTest, FindsTheRevisitOfTheStart) {
  const Vocabulary* vocabulary = DefaultVocabulary();
  if (vocabulary == nullptr) GTEST_SKIP() << "data/vocabulary/orb_k10_l5.bin is missing";
  // One and a half turns: keyframe 40 (360 degrees) is back at the start, with new points.
  Route scene(*vocabulary, 540.0);
  ASSERT_EQ(scene.keyframes.size(), 61u);
  const int revisit = FirstRevisit(scene);
  ASSERT_GE(revisit, 30);
  const RunSummary summary = FeedRoute(scene);
  std::printf(
      "first revisit %d, first detection: words %d, markers %d; candidates: words %d, "
      "markers %d, false %d\n",
      revisit, summary.first_word_detection, summary.first_marker_detection,
      summary.num_word_candidates, summary.num_marker_candidates, summary.num_false);
  EXPECT_EQ(summary.num_false, 0);
  // Consistency over 3 keyframes: two keyframes after the first revisit at the earliest,
  // and within 5 keyframes (45 degrees) of it.
  EXPECT_GE(summary.first_word_detection, revisit + 2);
  EXPECT_LE(summary.first_word_detection, revisit + 5);
  EXPECT_GE(summary.num_word_candidates, 10);
  // Marker 7 (30 degrees) comes back into view in the first keyframes of the revisit.
  EXPECT_GE(summary.first_marker_detection, revisit);
  EXPECT_LE(summary.first_marker_detection, revisit + 5);
  EXPECT_GE(summary.num_marker_candidates, 1);
}

TEST(LoopDetectorTest, ItsCandidateClosesTheLoop) {
  const Vocabulary* vocabulary = DefaultVocabulary();
  if (vocabulary == nullptr) GTEST_SKIP() << "data/vocabulary/orb_k10_l5.bin is missing";
  // Steps of 8.5 degrees: the second lap does not pass exactly through the first's poses.
  Route scene(*vocabulary, 450.0, 8.5);
  LoopDetector detector(scene.map, scene.database);
  std::optional<std::pair<KeyframeId, KeyframeId>> loop;
  for (std::size_t i = 0; i < scene.keyframes.size() && !loop; ++i) {
    scene.map.Read([&](const MapData& data) {
      scene.database.Add(*data.FindKeyframe(scene.keyframes[i]));
      return 0;
    });
    const std::vector<KeyframeId> found = detector.DetectByWords(scene.keyframes[i]);
    if (!found.empty()) loop = std::make_pair(scene.keyframes[i], found.front());
  }
  ASSERT_TRUE(loop.has_value());
  const std::size_t points_before = scene.map.NumMapPoints();
  LoopCloser closer(scene.map);
  const LoopClosureResult result = closer.CloseLoop(loop->first, loop->second);
  std::printf("loop %d -> %d: matches %d, sim3 inliers %d, projected %d, fused %d, scale %g\n",
              scene.IndexOf(loop->first), scene.IndexOf(loop->second), result.num_matches,
              result.num_sim3_inliers, result.num_projected_matches, result.num_fused_points,
              result.candidate_from_current.scale);
  ASSERT_TRUE(result.closed) << result.reason;
  // The map has no drift: the loop transform is the true relative pose; duplicates merge.
  const Rigid3 truth = scene.map.Read([&](const MapData& data) {
    return data.FindKeyframe(loop->second)->cam_from_world *
           data.FindKeyframe(loop->first)->cam_from_world.Inverse();
  });
  EXPECT_NEAR(result.candidate_from_current.scale, 1.0, 0.01);
  EXPECT_LT((result.candidate_from_current.translation - truth.translation).norm(), 0.05);
  EXPECT_LT(Eigen::AngleAxisd(result.candidate_from_current.rotation.conjugate() * truth.rotation)
                .angle(),
            0.005);
  EXPECT_GT(result.num_fused_points, 50);
  EXPECT_LT(scene.map.NumMapPoints(), points_before);
  EXPECT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

TEST(LoopDetectorTest, ConsistencyDelaysTheDetection) {
  const Vocabulary* vocabulary = DefaultVocabulary();
  if (vocabulary == nullptr) GTEST_SKIP() << "data/vocabulary/orb_k10_l5.bin is missing";
  Route once(*vocabulary, 450.0);
  LoopDetectorOptions immediate;
  immediate.min_consistent_keyframes = 1;
  const RunSummary first = FeedRoute(once, immediate);
  Route again(*vocabulary, 450.0);
  const RunSummary consistent = FeedRoute(again);
  EXPECT_EQ(first.num_false, 0);
  ASSERT_GE(first.first_word_detection, FirstRevisit(once));
  EXPECT_EQ(consistent.first_word_detection, first.first_word_detection + 2);
}

TEST(LoopDetectorTest, NoCandidateOnARouteWithoutRevisit) {
  const Vocabulary* vocabulary = DefaultVocabulary();
  if (vocabulary == nullptr) GTEST_SKIP() << "data/vocabulary/orb_k10_l5.bin is missing";
  // 0.8 of a turn: the end never sees what the start saw; both markers are seen once.
  Route scene(*vocabulary, 288.0);
  ASSERT_EQ(FirstRevisit(scene), -1);
  const RunSummary summary = FeedRoute(scene);
  EXPECT_EQ(summary.num_false, 0);
  EXPECT_EQ(summary.num_word_candidates, 0);
  EXPECT_EQ(summary.num_marker_candidates, 0);
  // Even without the consistency check nothing is proposed.
  Route again(*vocabulary, 288.0);
  LoopDetectorOptions immediate;
  immediate.min_consistent_keyframes = 1;
  EXPECT_EQ(FeedRoute(again, immediate).num_word_candidates, 0);
}

TEST(LoopDetectorTest, MarkerLookupSkipsNeighboursAndNewerKeyframes) {
  const Vocabulary* vocabulary = DefaultVocabulary();
  if (vocabulary == nullptr) GTEST_SKIP() << "data/vocabulary/orb_k10_l5.bin is missing";
  Route scene(*vocabulary, 288.0);
  // Keyframe 22 (198 degrees) sees marker 8; a lookup that also lists keyframe 1 (far
  // away), 19 and 21 (its covisible neighbours) and 30 (newer).
  const KeyframeId current = scene.keyframes[22];
  const auto index =
      scene.map.Read([](const MapData& data) { return BuildMarkerKeyframeIndex(data); });
  ASSERT_EQ(index.count(MarkerId(8)), 1u);
  const std::vector<KeyframeId>& seen = index.at(MarkerId(8));
  ASSERT_NE(std::find(seen.begin(), seen.end(), current), seen.end());
  LoopDetector detector(scene.map, scene.database);
  const auto lookup = [&](MarkerId marker) {
    if (marker != MarkerId(8)) return std::vector<KeyframeId>();
    return std::vector<KeyframeId>{scene.keyframes[1], scene.keyframes[19], scene.keyframes[21],
                                   scene.keyframes[30], current};
  };
  EXPECT_EQ(detector.DetectByMarkers(current, lookup), std::vector<KeyframeId>{scene.keyframes[1]});
  // A keyframe that saw no marker has no marker candidate.
  EXPECT_TRUE(detector.DetectByMarkers(scene.keyframes[12], lookup).empty());
}

TEST(LoopDetectorTest, OptionsCheck) {
  EXPECT_TRUE(LoopDetectorOptions{}.Check());
  LoopDetectorOptions bad;
  bad.min_consistent_keyframes = 0;
  EXPECT_FALSE(bad.Check());
  bad = {};
  bad.exclude_min_weight = 0;
  EXPECT_FALSE(bad.Check());
}

}  // namespace
}  // namespace arucoslam
