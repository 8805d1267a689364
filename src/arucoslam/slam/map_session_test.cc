// MapSession's decisions on a lost map (kept, reset, a new map after new_map_after_lost_s),
// what closing keeps, and the merge of a closed map into the next one: maps of keyframes along
// a circular route (synthetic_route_map.h), a few degrees of azimuth apart.
#include "arucoslam/slam/map_session.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "arucoslam/slam/synthetic_route_map.h"

namespace arucoslam {
namespace {

Frame FrameAt(double timestamp_s) {
  Frame frame;
  frame.timestamp_s = timestamp_s;
  return frame;
}

LostMapState Lost(std::size_t num_keyframes, bool world_aligned = false, bool fix = false) {
  LostMapState map;
  map.num_keyframes = num_keyframes;
  map.world_aligned = world_aligned;
  map.frame_has_marker_fix = fix;
  return map;
}

std::vector<StampedPose> Stamped(int count) {
  std::vector<StampedPose> poses(count);
  for (int i = 0; i < count; ++i) poses[i].timestamp_s = i;
  return poses;
}

// Keyframes along `route` at the given azimuths (degrees), added to `map`.
std::vector<KeyframeId> AddKeyframesAt(SyntheticRoute& route, const std::vector<double>& azimuths,
                                       Map* map) {
  std::vector<Rigid3> poses;
  for (const double azimuth : azimuths) poses.push_back(route.CamFromWorld(azimuth));
  return route.AddRoute(poses, map);
}

TEST(MapSession, YoungLostMapIsResetAndOlderOneReplacedAfterTheLossLasts) {
  MapSession session({}, /*marker_world=*/false);  // reset_max_keyframes 5, 1 s
  EXPECT_EQ(session.OnLostFrame(FrameAt(0.0), Lost(3)), LossAction::kReset);
  session.StartNewMap(std::nullopt);
  EXPECT_EQ(session.OnLostFrame(FrameAt(10.0), Lost(8)), LossAction::kKeep);
  EXPECT_EQ(session.OnLostFrame(FrameAt(10.5), Lost(8)), LossAction::kKeep);
  EXPECT_EQ(session.OnLostFrame(FrameAt(11.0), Lost(8)), LossAction::kNewMap);
  session.StartNewMap(std::nullopt);
  EXPECT_EQ(session.stats().num_resets, 2);
  EXPECT_EQ(session.stats().num_new_maps_after_loss, 1);
}

TEST(MapSession, TrackedFrameEndsTheLoss) {
  MapSessionOptions options;
  options.new_map_after_lost_s = 0.5;
  MapSession session(options, false);
  EXPECT_EQ(session.OnLostFrame(FrameAt(1.0), Lost(8)), LossAction::kKeep);
  session.OnTrackedFrame();
  // The loss starts again at 1.4 s: 0.5 s later, not 0.5 s after the first one.
  EXPECT_EQ(session.OnLostFrame(FrameAt(1.4), Lost(8)), LossAction::kKeep);
  EXPECT_EQ(session.OnLostFrame(FrameAt(1.6), Lost(8)), LossAction::kKeep);
  EXPECT_EQ(session.OnLostFrame(FrameAt(1.9), Lost(8)), LossAction::kNewMap);
}

TEST(MapSession, MapInTheWorldIsKeptUnlessMarkersKeepLocatingFramesItLost) {
  MapSession session({}, /*marker_world=*/true);  // marker_reset_lost_frames 10
  // Young but in the world: markers relocalise into it.
  EXPECT_EQ(session.OnLostFrame(FrameAt(0.0), Lost(3, true)), LossAction::kKeep);
  session.OnTrackedFrame();
  for (int i = 1; i <= 9; ++i) {
    EXPECT_EQ(session.OnLostFrame(FrameAt(0.05 * i), Lost(30, true, true)), LossAction::kKeep);
  }
  EXPECT_EQ(session.OnLostFrame(FrameAt(0.5), Lost(30, true, true)), LossAction::kReset);
}

TEST(MapSession, LoadedMapIsKeptHoweverLongTheLoss) {
  MapSession session({}, false);
  LostMapState loaded = Lost(2);
  loaded.loaded = true;
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(session.OnLostFrame(FrameAt(1.0 * i), loaded), LossAction::kKeep);
  }
}

TEST(MapSession, KeypointMapsKeepTheBiggestClosedOneAsOutput) {
  MapSession session({}, /*marker_world=*/false);
  EXPECT_EQ(session.DecideClosing(0, false), MapClosing::kNothing);
  ASSERT_EQ(session.DecideClosing(8, false), MapClosing::kBiggestKeypointMap);
  session.KeepBiggestKeypointMap(Stamped(40), 8);
  EXPECT_EQ(session.DecideClosing(6, false), MapClosing::kNothing);
  const std::vector<StampedPose>* output = session.BiggerClosedMapPoses(6);
  ASSERT_NE(output, nullptr);
  EXPECT_EQ(output->size(), 40u);
  EXPECT_EQ(session.BiggerClosedMapPoses(8), nullptr);  // the current map is as big
}

TEST(MapSession, MarkerWorldDiscardsUnalignedMapsAndClosesAlignedOnes) {
  MapSession session({}, /*marker_world=*/true);
  EXPECT_EQ(session.DecideClosing(8, /*world_aligned=*/false), MapClosing::kDiscarded);
  EXPECT_EQ(session.DecideClosing(8, /*world_aligned=*/true), MapClosing::kInWorld);
  EXPECT_EQ(session.stats().num_maps_discarded, 1);
  EXPECT_EQ(session.BiggerClosedMapPoses(0), nullptr);
}

TEST(MapSession, ClosedWorldMapIsMergedIntoTheNextMapInTheWorld) {
  SyntheticRoute route;
  MapSession session({}, /*marker_world=*/true);
  // An older closed map whose merge never came: it stays in the outputs.
  ClosingWorldMap older;
  older.keyframes = Stamped(4);
  older.points.assign(100, Eigen::Vector3d::Zero());
  Map older_map;
  AddKeyframesAt(route, {90.0, 93.0}, &older_map);
  ASSERT_TRUE(session.CloseWorldMap(older_map, older));
  session.StartNewMap(0);

  Map closed_map;
  const std::vector<KeyframeId> closed_ids =
      AddKeyframesAt(route, {0.0, 3.0, 6.0, 9.0, 12.0}, &closed_map);
  ClosingWorldMap closing;
  closing.keyframes = Stamped(4 + 5);
  closing.points.assign(100 + 300, Eigen::Vector3d::Zero());
  MarkerFix fix;
  fix.world_from_cam.translation = Eigen::Vector3d(1.0, 2.0, 3.0);
  closing.keyframe_fixes[closed_ids[2]] = fix;
  ASSERT_TRUE(session.CloseWorldMap(closed_map, closing));
  session.StartNewMap(1);  // the marker mapper's generation of the closed map
  EXPECT_EQ(session.closed_keyframes().size(), 9u);

  Map current;
  const std::vector<KeyframeId> current_ids = AddKeyframesAt(route, {30.0, 33.0, 36.0}, &current);
  const std::size_t closed_points = closed_map.NumMapPoints();
  const std::size_t current_points = current.NumMapPoints();
  const std::optional<MergedClosedMap> merged = session.MergeClosedMap(current);
  ASSERT_TRUE(merged.has_value());
  EXPECT_EQ(merged->ids.keyframes.size(), 5u);
  EXPECT_EQ(current.NumKeyframes(), 8u);
  EXPECT_EQ(current.NumMapPoints(), closed_points + current_points);
  EXPECT_EQ(merged->attached_to, current_ids[0]);  // azimuth 30 is nearest azimuth 0
  EXPECT_EQ(merged->marker_generation, 1);
  ASSERT_EQ(merged->keyframe_fixes.size(), 1u);
  const KeyframeId fixed = merged->ids.keyframes.at(closed_ids[2]);
  EXPECT_EQ(merged->keyframe_fixes.begin()->first, fixed);
  EXPECT_EQ(merged->keyframe_fixes.begin()->second.world_from_cam.translation.y(), 2.0);
  // The merged map's outputs are the current map's now; the older map's stay.
  EXPECT_EQ(session.closed_keyframes().size(), 4u);
  EXPECT_EQ(session.closed_points().size(), 100u);
  EXPECT_EQ(session.absorbed_keyframes().size(), 5u);
  EXPECT_EQ(session.absorbed_keyframes().count(fixed), 1u);
  EXPECT_EQ(session.stats().num_map_merges, 1);
  EXPECT_FALSE(session.MergeClosedMap(current).has_value());  // merged once

  // No point links the two parts until a current keyframe observes an absorbed point.
  EXPECT_FALSE(session.LinkedToAbsorbedMap(current));
  const bool observed = current.Write([&](MapData& data) {
    const MapPointId absorbed_point = data.MapPointsOf(fixed).front();
    return data.AddObservation(current_ids[0], 0, absorbed_point);
  });
  ASSERT_TRUE(observed);
  EXPECT_TRUE(session.LinkedToAbsorbedMap(current));

  session.StartNewMap(std::nullopt);
  EXPECT_TRUE(session.absorbed_keyframes().empty());
}

TEST(MapSession, WithoutMergesAClosedMapStaysInTheOutputsOnly) {
  MapSessionOptions options;
  options.merge_closed_maps = false;
  MapSession session(options, /*marker_world=*/true);
  SyntheticRoute route;
  Map closed_map;
  AddKeyframesAt(route, {0.0, 3.0, 6.0}, &closed_map);
  ClosingWorldMap closing;
  closing.keyframes = Stamped(3);
  EXPECT_FALSE(session.CloseWorldMap(closed_map, closing));
  session.StartNewMap(std::nullopt);
  Map current;
  AddKeyframesAt(route, {30.0, 33.0}, &current);
  EXPECT_FALSE(session.MergeClosedMap(current).has_value());
  EXPECT_EQ(current.NumKeyframes(), 2u);
  EXPECT_EQ(session.closed_keyframes().size(), 3u);
}

TEST(MapSessionOptions, CheckNamesTheField) {
  EXPECT_TRUE(MapSessionOptions().Check());
  struct Case {
    const char* field;
    void (*spoil)(MapSessionOptions&);
  };
  const Case cases[] = {
      {"bridge_position_sigma_m", [](MapSessionOptions& o) { o.bridge_position_sigma_m = -0.01; }},
      {"bridge_rotation_sigma_per_s",
       [](MapSessionOptions& o) { o.bridge_rotation_sigma_per_s = -0.5; }},
      {"new_map_after_lost_s", [](MapSessionOptions& o) { o.new_map_after_lost_s = 0.0; }},
      // below bridge_motion.min_span_s
      {"bridge_motion.max_span_s", [](MapSessionOptions& o) { o.bridge_motion.max_span_s = 0.1; }},
      {"max_backfill_frames", [](MapSessionOptions& o) { o.max_backfill_frames = -1; }},
      {"marker_reset_lost_frames", [](MapSessionOptions& o) { o.marker_reset_lost_frames = 0; }},
  };
  for (const Case& test : cases) {
    MapSessionOptions options;
    test.spoil(options);
    std::string why;
    EXPECT_FALSE(options.Check(&why)) << test.field;
    EXPECT_NE(why.find(test.field), std::string::npos) << why;
  }
}

}  // namespace
}  // namespace arucoslam
