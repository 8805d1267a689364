// MapLifecycle on maps of keyframes along a circular route (synthetic_route_map.h): a saved
// map started from, lost maps reset, closed and merged into the next map in the world, the
// biggest keypoint map kept as output, and the place database's lock for a map move.
#include "arucoslam/slam/map_lifecycle.h"

#include <gtest/gtest.h>

#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "arucoslam/slam/flow_test_doubles.h"
#include "arucoslam/slam/synthetic_marker_scene.h"
#include "arucoslam/slam/synthetic_route_map.h"

namespace arucoslam {
namespace {

using test_doubles::ScriptedPlaces;

// The objects FrameFlow lends the lifecycle, replaced on a reset as FrameFlow does; each map
// gets a new ScriptedPlaces when `with_places`.
class LifecycleHarness {
 public:
  LifecycleHarness(bool markers, bool with_places)
      : options_(Options(markers)),
        pose_history_(/*keep_matches=*/false, [](KeyframeId) { return 1.0; }),
        marker_fusion_(options_.marker_fusion, SyntheticRoute::Camera(), MarkerMap(), 0.0),
        anchoring_(options_.world_anchoring),
        marker_mapping_(options_.marker_map, options_.marker_mapping),
        lifecycle_(
            options_,
            [this, with_places](Map&) -> std::unique_ptr<PlaceIndex> {
              ++num_place_indexes;
              if (!with_places) return nullptr;
              auto places = std::make_unique<ScriptedPlaces>();
              places_ = places.get();
              return places;
            },
            &stats_, &stats_mutex_) {
    lifecycle_.MakePlaces(Parts());
  }

  static FrameFlowOptions Options(bool markers) {
    FrameFlowOptions options;
    if (markers) options.marker_map = test_scene::SceneMarkers();
    return options;
  }

  MapLifecycleParts Parts() {
    return {*map_, *tracker_, pose_history_, anchoring_, marker_fusion_, marker_mapping_};
  }

  // Keyframes along the route at the given azimuths (degrees), each with a frame pose
  // recorded on it.
  void AddKeyframesAt(const std::vector<double>& azimuths) {
    std::vector<Rigid3> poses;
    for (const double azimuth : azimuths) poses.push_back(route_.CamFromWorld(azimuth));
    const std::vector<KeyframeId> ids = route_.AddRoute(poses, map_.get());
    for (std::size_t i = 0; i < ids.size(); ++i) {
      Frame frame;
      frame.timestamp_s = next_timestamp_s_;
      next_timestamp_s_ += 0.1;
      frame.cam_from_world = poses[i];
      pose_history_.Record(*map_, frame, ids[i], anchoring_.aligned(), std::nullopt);
    }
  }

  // A lost frame at `timestamp_s`; true when the lifecycle wants the map reset.
  bool Lose(double timestamp_s) {
    Frame frame;
    frame.timestamp_s = timestamp_s;
    return lifecycle_.OnLostFrame(Parts(), frame, 0);
  }

  // The map replaced by an empty one as FrameFlow does; true when the old one was kept whole
  // for a merge.
  bool ResetMap() {
    const bool kept_for_merge = lifecycle_.CloseMap(Parts());
    tracker_.reset();
    map_ = std::make_unique<Map>();
    tracker_ = std::make_unique<Tracker>(*map_, options_.tracker);
    lifecycle_.StartNewMap(Parts(), kept_for_merge);
    anchoring_.Reset();
    return kept_for_merge;
  }

  MapLifecycle& lifecycle() { return lifecycle_; }
  Map& map() { return *map_; }
  WorldAnchoring& anchoring() { return anchoring_; }
  ScriptedPlaces* places() { return places_; }

  int num_place_indexes = 0;

 private:
  FrameFlowOptions options_;
  FrameFlowStats stats_;
  std::mutex stats_mutex_;
  SyntheticRoute route_;
  double next_timestamp_s_ = 0.0;
  std::unique_ptr<Map> map_ = std::make_unique<Map>();
  std::unique_ptr<Tracker> tracker_ = std::make_unique<Tracker>(*map_, options_.tracker);
  PoseHistory pose_history_;
  MarkerFusion marker_fusion_;
  WorldAnchoring anchoring_;
  OnlineMarkerMapping marker_mapping_;
  ScriptedPlaces* places_ = nullptr;
  MapLifecycle lifecycle_;  // last: its places go before the map
};

TEST(MapLifecycle, ALostWorldMapIsClosedAndTheNextAlignedMapMergesIt) {
  LifecycleHarness harness(/*markers=*/true, /*with_places=*/true);
  harness.anchoring().AlignedFromMarkers();
  harness.AddKeyframesAt({0.0, 3.0, 6.0, 9.0, 12.0});
  // Not young: kept while lost, until new_map_after_lost_s (1 s).
  EXPECT_FALSE(harness.Lose(10.0));
  EXPECT_FALSE(harness.Lose(10.5));
  EXPECT_TRUE(harness.Lose(11.0));
  EXPECT_TRUE(harness.ResetMap());
  const MapSession& session = harness.lifecycle().session();
  EXPECT_EQ(session.stats().num_new_maps_after_loss, 1);
  EXPECT_EQ(harness.map().NumKeyframes(), 0u);
  EXPECT_EQ(harness.num_place_indexes, 2);
  // The closed map stays in the outputs while the new one is outside the world.
  EXPECT_EQ(harness.lifecycle().KeyframePoses(harness.map(), false).size(), 5u);

  harness.AddKeyframesAt({30.0, 33.0, 36.0});
  harness.anchoring().AlignedFromMarkers();
  const std::size_t new_points = harness.map().NumMapPoints();
  ASSERT_TRUE(harness.lifecycle().MergeClosedMap(harness.Parts()));
  EXPECT_EQ(harness.map().NumKeyframes(), 8u);
  EXPECT_GT(harness.map().NumMapPoints(), new_points);
  EXPECT_EQ(session.stats().num_map_merges, 1);
  EXPECT_EQ(session.absorbed_keyframes().size(), 5u);
  // The absorbed keyframes enter the new map's places under their new ids.
  ASSERT_NE(harness.places(), nullptr);
  EXPECT_EQ(harness.places()->indexed.size(), 5u);
  EXPECT_EQ(session.absorbed_keyframes().count(harness.places()->indexed.front()), 1u);
  // Each keyframe once in the outputs, and in time order.
  const std::vector<StampedPose> keyframes = harness.lifecycle().KeyframePoses(harness.map(), true);
  ASSERT_EQ(keyframes.size(), 8u);
  for (std::size_t i = 1; i < keyframes.size(); ++i) {
    EXPECT_LE(keyframes[i - 1].timestamp_s, keyframes[i].timestamp_s);
  }
  EXPECT_FALSE(harness.lifecycle().MergeClosedMap(harness.Parts()));  // merged once
}

TEST(MapLifecycle, AYoungMapIsResetAtOnceAndAnUnalignedOneLeavesNothing) {
  LifecycleHarness harness(/*markers=*/true, /*with_places=*/false);
  harness.AddKeyframesAt({0.0, 3.0, 6.0});  // at most reset_max_keyframes (5)
  EXPECT_TRUE(harness.Lose(1.0));
  EXPECT_FALSE(harness.ResetMap());
  EXPECT_EQ(harness.lifecycle().session().stats().num_maps_discarded, 1);
  EXPECT_TRUE(harness.lifecycle().KeyframePoses(harness.map(), false).empty());
  EXPECT_TRUE(harness.lifecycle().MapPoints(harness.map(), false).empty());
  EXPECT_EQ(harness.lifecycle().places(), nullptr);
}

TEST(MapLifecycle, KeypointRunsKeepTheBiggestLostMapAsOutput) {
  LifecycleHarness harness(/*markers=*/false, /*with_places=*/false);
  harness.AddKeyframesAt({0.0, 3.0, 6.0, 9.0, 12.0, 15.0, 18.0, 21.0});
  const std::size_t points = harness.map().NumMapPoints();
  EXPECT_FALSE(harness.Lose(10.0));
  EXPECT_TRUE(harness.Lose(11.0));
  EXPECT_FALSE(harness.ResetMap());
  const MapSession& session = harness.lifecycle().session();
  // Until the new map is as big, the old map's eight poses are the output.
  const std::vector<StampedPose>* closed = session.BiggerClosedMapPoses(7);
  ASSERT_NE(closed, nullptr);
  EXPECT_EQ(closed->size(), 8u);
  EXPECT_EQ(session.BiggerClosedMapPoses(8), nullptr);
  // Without markers the current map is always in the outputs: only its own points.
  harness.AddKeyframesAt({40.0, 43.0});
  EXPECT_EQ(harness.lifecycle().KeyframePoses(harness.map(), false).size(), 2u);
  EXPECT_LT(harness.lifecycle().MapPoints(harness.map(), false).size(), points);
}

TEST(MapLifecycle, ASavedMapIsIndexedAndKeptHoweverLongTheLoss) {
  LifecycleHarness builder(/*markers=*/false, /*with_places=*/false);
  builder.AddKeyframesAt({0.0, 3.0, 6.0, 9.0, 12.0, 15.0});
  MapData saved = builder.map().Read([](const MapData& data) { return data; });

  LifecycleHarness harness(/*markers=*/false, /*with_places=*/true);
  harness.lifecycle().StartFromMap(harness.Parts(), std::move(saved), /*world_aligned=*/true,
                                   /*localize_only=*/true);
  EXPECT_EQ(harness.map().NumKeyframes(), 6u);
  EXPECT_TRUE(harness.lifecycle().map_loaded());
  EXPECT_TRUE(harness.lifecycle().localize_only());
  EXPECT_TRUE(harness.anchoring().aligned());
  ScriptedPlaces* places = harness.places();
  ASSERT_NE(places, nullptr);
  EXPECT_EQ(places->num_existing_indexed, 1);
  EXPECT_EQ(places->metric, std::optional<bool>(true));
  EXPECT_FALSE(harness.Lose(0.0));
  EXPECT_FALSE(harness.Lose(60.0));
  // The places offer nothing: neither they nor the keyframe matching (places exist) relocalise.
  Frame frame;
  FrameReport report;
  EXPECT_FALSE(harness.lifecycle().RelocalizeWithPlaces(harness.Parts(), frame, report));
  EXPECT_FALSE(harness.lifecycle().RelocalizeInLoadedMap(harness.Parts(), frame, report));
  EXPECT_EQ(places->num_queries, 1);
  EXPECT_EQ(places->num_taken, 0);
  EXPECT_TRUE(report.message.empty());
}

TEST(MapLifecycle, AMapMoveHoldsThePlaceEditsAndMakesTheMapMetric) {
  LifecycleHarness harness(/*markers=*/true, /*with_places=*/true);
  ScriptedPlaces* places = harness.places();
  ASSERT_NE(places, nullptr);
  {
    const std::unique_lock<std::mutex> lock = harness.lifecycle().LockPlacesForMapMove();
    EXPECT_TRUE(lock.owns_lock());
    EXPECT_EQ(places->num_external_moves, 1);
    EXPECT_EQ(places->metric, std::optional<bool>(true));
  }
  LifecycleHarness without(/*markers=*/true, /*with_places=*/false);
  EXPECT_FALSE(without.lifecycle().LockPlacesForMapMove().owns_lock());
}

}  // namespace
}  // namespace arucoslam
