#include "arucoslam/slam/keyframe_database.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <optional>

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

using Match = TypedPlaceDatabase<KeyframeId>::Match;

TEST(GroupCandidatesTest, AccumulatesScoresOverCovisibleKeyframes) {
  CovisibilityGraph graph;
  for (int id : {1, 2, 3, 10}) graph.AddKeyframe(KeyframeId(id));
  graph.AddToWeight(KeyframeId(1), KeyframeId(2), 40);
  graph.AddToWeight(KeyframeId(2), KeyframeId(3), 30);
  graph.AddToWeight(KeyframeId(1), KeyframeId(3), 20);
  // Keyframe 10 scores best alone; the place seen by 1, 2, 3 wins as a group.
  const std::vector<Match> matches = {{KeyframeId(10), 0.35, 100},
                                      {KeyframeId(1), 0.30, 95},
                                      {KeyframeId(2), 0.25, 90},
                                      {KeyframeId(3), 0.20, 85}};
  std::vector<PlaceCandidate> candidates = GroupCandidates(matches, graph);
  ASSERT_EQ(candidates.size(), 1u);
  EXPECT_EQ(candidates[0].keyframe, KeyframeId(1));
  EXPECT_NEAR(candidates[0].score, 0.30, 1e-12);
  EXPECT_NEAR(candidates[0].group_score, 0.75, 1e-12);
  // A laxer group ratio keeps keyframe 10 too (0.35 >= 0.4 x 0.75), ranked second.
  CandidateGroupingOptions lax;
  lax.min_group_score_ratio = 0.4;
  candidates = GroupCandidates(matches, graph, lax);
  ASSERT_EQ(candidates.size(), 2u);
  EXPECT_EQ(candidates[1].keyframe, KeyframeId(10));
  EXPECT_NEAR(candidates[1].group_score, 0.35, 1e-12);
}

TEST(GroupCandidatesTest, DropsMatchesSharingFewWords) {
  CovisibilityGraph graph;
  for (int id : {1, 2}) graph.AddKeyframe(KeyframeId(id));
  // Keyframe 2 shares 70 words, below 0.8 x 100: it is dropped before grouping.
  const std::vector<Match> matches = {{KeyframeId(1), 0.10, 100}, {KeyframeId(2), 0.50, 70}};
  const std::vector<PlaceCandidate> candidates = GroupCandidates(matches, graph);
  ASSERT_EQ(candidates.size(), 1u);
  EXPECT_EQ(candidates[0].keyframe, KeyframeId(1));
  EXPECT_TRUE(GroupCandidates({}, graph).empty());
}

TEST(GroupCandidatesTest, OptionsCheck) {
  EXPECT_TRUE(CandidateGroupingOptions{}.Check());
  CandidateGroupingOptions bad;
  bad.min_group_score_ratio = 0.0;
  EXPECT_FALSE(bad.Check());
  bad = {};
  bad.max_candidates = 0;
  EXPECT_FALSE(bad.Check());
}

TEST(KeyframeDatabaseTest, FindsTheKeyframeOfTheSamePlace) {
  const Vocabulary* vocabulary = DefaultVocabulary();
  if (vocabulary == nullptr) GTEST_SKIP() << "data/vocabulary/orb_k10_l5.bin is missing";
  SyntheticRoute route;
  Map map;
  std::vector<Rigid3> poses;
  for (double azimuth = 0.0; azimuth <= 180.0; azimuth += 20.0) {
    poses.push_back(route.CamFromWorld(azimuth));
  }
  const std::vector<KeyframeId> ids = route.AddRoute(poses, &map);
  KeyframeDatabase database(*vocabulary);
  map.Read([&](const MapData& data) {
    for (const KeyframeId& id : ids) database.Add(*data.FindKeyframe(id));
    return 0;
  });
  ASSERT_EQ(database.size(), ids.size());
  ASSERT_NE(database.Direct(ids[3]), nullptr);
  EXPECT_FALSE(database.Direct(ids[3])->groups.empty());
  // A new image of the place of keyframe 3 (60 degrees): it is the best match.
  std::vector<int> truth;
  const Frame frame = route.MakeFrame(FrameId(100), route.CamFromWorld(62.0), 100, &truth);
  const ImageWords words = database.Transform(frame.features.descriptors);
  EXPECT_NEAR(words.bow.L1Norm(), 1.0, 1e-9);
  const auto matches = database.Query(words.bow);
  ASSERT_FALSE(matches.empty());
  EXPECT_EQ(matches[0].id, ids[3]);
  // A keyframe's own words score 1.
  const auto self = database.Query(*database.Bow(ids[5]));
  ASSERT_FALSE(self.empty());
  EXPECT_EQ(self[0].id, ids[5]);
  EXPECT_NEAR(self[0].score, 1.0, 1e-9);
  EXPECT_TRUE(database.Erase(ids[3]));
  EXPECT_FALSE(database.Erase(ids[3]));
  EXPECT_FALSE(database.Contains(ids[3]));
  EXPECT_NE(database.Query(words.bow)[0].id, ids[3]);
}

}  // namespace
}  // namespace arucoslam
