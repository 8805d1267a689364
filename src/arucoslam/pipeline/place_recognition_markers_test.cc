// Marker ids as place words: a lost frame whose place the keyframe database cannot find
// (its keyframes are not in it yet) is relocalised from the keyframes that saw its markers.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>

#include "arucoslam/pipeline/place_recognition.h"
#include "arucoslam/slam/synthetic_route_map.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

std::shared_ptr<const Vocabulary> ShippedVocabulary() {
  const fs::path path = fs::path(ARUCOSLAM_SOURCE_DIR) / "data" / "vocabulary" / "orb_k10_l5.bin";
  if (!fs::exists(path)) return nullptr;
  return std::make_shared<const Vocabulary>(Vocabulary::Load(path));
}

struct Outcome {
  std::optional<RelocalizationResult> result;
  std::vector<KeyframeId> keyframes;  // of the route, azimuth 0 to 90 every 9 degrees
  std::vector<KeyframeId> seeing_marker;  // those that saw marker 7
};

// The route's keyframes are mapped, but only the last three (azimuth 72-90) are in the
// database; the frame is lost at azimuth 40.5, 6 degrees turned and 0.4 m off the route,
// and sees marker 7 (at azimuth 40) unless `hide_markers`.
Outcome RelocaliseLostFrame(std::shared_ptr<const Vocabulary> vocabulary,
                            int max_marker_candidates, bool hide_markers, Rigid3* truth) {
  SyntheticRouteOptions route_options;
  route_options.markers = {{7, 40.0}};
  SyntheticRoute route(route_options);
  Map map;
  std::vector<Rigid3> poses;
  for (int k = 0; k <= 10; ++k) poses.push_back(route.CamFromWorld(9.0 * k));
  Outcome outcome;
  outcome.keyframes = route.AddRoute(poses, &map);
  map.Read([&](const MapData& data) {
    for (const KeyframeId& id : outcome.keyframes) {
      if (!data.FindKeyframe(id)->markers.empty()) outcome.seeing_marker.push_back(id);
    }
    return 0;
  });
  PlaceRecognitionOptions options;
  options.loop_closing = false;
  options.max_marker_candidates = max_marker_candidates;
  PlaceRecognitionStats stats;
  std::mutex stats_mutex;
  PlaceRecognition places(map, std::move(vocabulary), options, false, &stats, &stats_mutex);
  for (std::size_t k = 8; k < outcome.keyframes.size(); ++k) {
    places.KeyframeMapped(outcome.keyframes[k]);
  }
  *truth = route.CamFromWorld(40.5, 6.0, 0.4);
  std::vector<int> truth_points;
  Frame frame = route.MakeFrame(FrameId(500), *truth, 150, &truth_points);
  if (hide_markers) frame.markers.clear();
  outcome.result = places.Relocalize(frame);
  places.Finish();
  return outcome;
}

TEST(PlaceRecognitionMarkers, LostFrameIsRelocalisedFromKeyframesSharingItsMarkers) {
  const std::shared_ptr<const Vocabulary> vocabulary = ShippedVocabulary();
  if (!vocabulary) GTEST_SKIP() << "data/vocabulary/orb_k10_l5.bin is missing";
  Rigid3 truth;
  const Outcome found = RelocaliseLostFrame(vocabulary, 5, false, &truth);
  ASSERT_FALSE(found.seeing_marker.empty());
  ASSERT_TRUE(found.result.has_value());
  EXPECT_GE(found.result->num_inliers, 50);
  const double error =
      (found.result->cam_from_world.Inverse().translation - truth.Inverse().translation).norm();
  EXPECT_LT(error, 0.02);  // hundreds of exact wall points at 5-7 m
  EXPECT_NE(std::find(found.seeing_marker.begin(), found.seeing_marker.end(),
                      found.result->keyframe),
            found.seeing_marker.end());
  // Without the marker words (turned off, or no marker in view) the database alone fails.
  EXPECT_FALSE(RelocaliseLostFrame(vocabulary, 0, false, &truth).result.has_value());
  EXPECT_FALSE(RelocaliseLostFrame(vocabulary, 5, true, &truth).result.has_value());
}

}  // namespace
}  // namespace arucoslam
