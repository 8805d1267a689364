#include "arucoslam/slam/relocalizer.h"

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

// A mapped arc: keyframes every 9 degrees from azimuth 0 to 90 on the route circle.
struct MappedArc {
  SyntheticRoute route;
  Map map;
  std::vector<KeyframeId> keyframes;
  std::optional<KeyframeDatabase> database;

  explicit MappedArc(const Vocabulary& vocabulary, std::uint32_t seed = 5)
      : route([seed] {
          SyntheticRouteOptions options;
          options.seed = seed;
          return options;
        }()) {
    std::vector<Rigid3> poses;
    for (int k = 0; k <= 10; ++k) poses.push_back(route.CamFromWorld(9.0 * k));
    keyframes = route.AddRoute(poses, &map);
    database.emplace(vocabulary);
    map.Read([&](const MapData& data) {
      for (const KeyframeId& id : keyframes) database->Add(*data.FindKeyframe(id));
      return 0;
    });
  }
};

double CentreError(const Rigid3& a, const Rigid3& b) {
  return (a.Inverse().translation - b.Inverse().translation).norm();
}

double AngleError(const Rigid3& a, const Rigid3& b) {
  return Eigen::AngleAxisd(a.rotation.conjugate() * b.rotation).angle();
}

TEST(RelocalizerTest, RelocalisesAFrameOfTheMappedPlace) {
  const Vocabulary* vocabulary = DefaultVocabulary();
  if (vocabulary == nullptr) GTEST_SKIP() << "data/vocabulary/orb_k10_l5.bin is missing";
  MappedArc arc(*vocabulary);
  // Lost between keyframes 4 and 5, turned 6 degrees and 0.4 m off the route.
  const Rigid3 truth = arc.route.CamFromWorld(40.5, 6.0, 0.4);
  std::vector<int> truth_points;
  const Frame frame = arc.route.MakeFrame(FrameId(500), truth, 150, &truth_points);
  const Relocalizer relocalizer(arc.map, *arc.database);
  RelocalizationStats stats;
  const std::optional<RelocalizationResult> result = relocalizer.Relocalize(frame, &stats);
  std::printf("database matches %d, candidates %d, bow %d, pnp %d, inliers %d\n",
              stats.num_database_matches, stats.num_candidates, stats.best_bow_matches,
              stats.best_pnp_inliers, stats.best_inliers);
  ASSERT_TRUE(result.has_value());
  EXPECT_GE(result->num_inliers, 50);
  // Hundreds of exact points seen with 0.3 px noise at 5-7 m: centimetre, 0.1 degree.
  EXPECT_LT(CentreError(result->cam_from_world, truth), 0.02);
  EXPECT_LT(AngleError(result->cam_from_world, truth), 0.002);
  // The reference keyframe is one of the two the frame lies between, or their neighbours.
  const auto position = std::find(arc.keyframes.begin(), arc.keyframes.end(), result->keyframe);
  ASSERT_NE(position, arc.keyframes.end());
  EXPECT_NEAR(static_cast<double>(position - arc.keyframes.begin()), 4.5, 2.0);
  // Every inlier is the map point of the keypoint's true wall point.
  ASSERT_EQ(result->map_point_ids.size(), frame.features.size());
  int num_valid = 0, num_wrong = 0;
  arc.map.Read([&](const MapData& data) {
    for (std::size_t i = 0; i < result->map_point_ids.size(); ++i) {
      const MapPoint* point = data.FindMapPoint(result->map_point_ids[i]);
      if (point == nullptr) continue;
      ++num_valid;
      if (truth_points[i] < 0 ||
          (point->p_in_world - arc.route.wall()[truth_points[i]]).norm() > 1e-9) {
        ++num_wrong;
      }
    }
    return 0;
  });
  EXPECT_EQ(num_valid, result->num_inliers);
  EXPECT_LE(num_wrong, 1);
}

TEST(RelocalizerTest, GuidedSearchRecoversTheMatchesBowMatchingMissed) {
  const Vocabulary* vocabulary = DefaultVocabulary();
  if (vocabulary == nullptr) GTEST_SKIP() << "data/vocabulary/orb_k10_l5.bin is missing";
  MappedArc arc(*vocabulary);
  // BoW matching restricted to near-identical descriptors: it finds a minority of the
  // matches, PnP starts from those and the projection search must find the rest.
  RelocalizerOptions options;
  options.max_bow_distance = 1;
  options.min_inliers = 150;
  const Relocalizer relocalizer(arc.map, *arc.database, options);
  const Rigid3 truth = arc.route.CamFromWorld(58.0, -4.0, -0.3);
  std::vector<int> truth_points;
  const Frame frame = arc.route.MakeFrame(FrameId(7), truth, 150, &truth_points);
  RelocalizationStats stats;
  const std::optional<RelocalizationResult> result = relocalizer.Relocalize(frame, &stats);
  std::printf("bow %d, pnp %d, inliers %d\n", stats.best_bow_matches, stats.best_pnp_inliers,
              stats.best_inliers);
  ASSERT_TRUE(result.has_value());
  EXPECT_LT(stats.best_pnp_inliers, 120);
  EXPECT_GE(result->num_inliers, 150);
  EXPECT_LT(CentreError(result->cam_from_world, truth), 0.02);
  EXPECT_LT(AngleError(result->cam_from_world, truth), 0.002);
}

TEST(RelocalizerTest, UnmappedPlacesAreNotRelocalised) {
  const Vocabulary* vocabulary = DefaultVocabulary();
  if (vocabulary == nullptr) GTEST_SKIP() << "data/vocabulary/orb_k10_l5.bin is missing";
  MappedArc arc(*vocabulary);
  const Relocalizer relocalizer(arc.map, *arc.database);
  std::vector<int> truth;
  // The same world, looking at a part of the wall the arc never saw.
  const Frame elsewhere =
      arc.route.MakeFrame(FrameId(1), arc.route.CamFromWorld(220.0), 150, &truth);
  RelocalizationStats stats;
  EXPECT_FALSE(relocalizer.Relocalize(elsewhere, &stats).has_value());
  EXPECT_LT(stats.best_inliers, 50);
  // Another world altogether (a different wall) seen from a mapped pose.
  SyntheticRouteOptions other_options;
  other_options.seed = 99;
  SyntheticRoute other(other_options);
  const Frame stranger = other.MakeFrame(FrameId(2), other.CamFromWorld(45.0), 150, &truth);
  EXPECT_FALSE(relocalizer.Relocalize(stranger, &stats).has_value());
  // A frame without features.
  Frame empty;
  empty.camera = SyntheticRoute::Camera();
  EXPECT_FALSE(relocalizer.Relocalize(empty).has_value());
}

TEST(RelocalizerTest, CandidatesAreTheKeyframesOfThePlace) {
  const Vocabulary* vocabulary = DefaultVocabulary();
  if (vocabulary == nullptr) GTEST_SKIP() << "data/vocabulary/orb_k10_l5.bin is missing";
  MappedArc arc(*vocabulary);
  const Relocalizer relocalizer(arc.map, *arc.database);
  std::vector<int> truth;
  const Frame frame = arc.route.MakeFrame(FrameId(1), arc.route.CamFromWorld(72.0), 150, &truth);
  const std::vector<KeyframeId> candidates =
      relocalizer.Candidates(arc.database->Transform(frame.features.descriptors).bow);
  ASSERT_FALSE(candidates.empty());
  // The frame sits on keyframe 8 (72 degrees): the best group is represented by it or by a
  // keyframe one step away.
  const auto position = std::find(arc.keyframes.begin(), arc.keyframes.end(), candidates[0]);
  ASSERT_NE(position, arc.keyframes.end());
  EXPECT_NEAR(static_cast<double>(position - arc.keyframes.begin()), 8.0, 1.0);
}

TEST(RelocalizerTest, OptionsCheck) {
  EXPECT_TRUE(RelocalizerOptions{}.Check());
  RelocalizerOptions bad;
  bad.min_bow_matches = 3;
  EXPECT_FALSE(bad.Check());
  bad = {};
  bad.pnp_confidence = 1.0;
  EXPECT_FALSE(bad.Check());
}

}  // namespace
}  // namespace arucoslam
