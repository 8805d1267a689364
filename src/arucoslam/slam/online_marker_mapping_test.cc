// OnlineMarkerMapping on a corridor with four markers, only the first known: which markers the
// aligned keyframes and the marker views map, when mapped ones start to locate frames, and
// what a closed map or a live one refuses.
#include "arucoslam/slam/online_marker_mapping.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "arucoslam/optim/marker_bundle_adjustment_synthetic.h"

namespace arucoslam {
namespace {

struct Corridor {
  MarkerBundleAdjustmentProblem truth;
  CameraModel camera;
  std::vector<std::vector<MarkerObservation>> markers;  // per camera pose
  // Per camera pose: where its markers locate it, millimetres and milliradians off the truth.
  std::vector<Rigid3> marker_cam_from_world;
};

Corridor MakeCorridor() {
  SyntheticMarkerSceneOptions options;
  options.corner_noise_px = 0.3;
  Corridor corridor;
  corridor.truth = MakeSyntheticMarkerScene(options);
  const PinholeIntrinsics& k = corridor.truth.keypoints.intrinsics;
  corridor.camera.width = options.image_width;
  corridor.camera.height = options.image_height;
  corridor.camera.fx = k.fx;
  corridor.camera.fy = k.fy;
  corridor.camera.cx = k.cx;
  corridor.camera.cy = k.cy;
  corridor.markers.resize(corridor.truth.keypoints.poses.size());
  for (const auto& observation : corridor.truth.marker_observations) {
    corridor.markers[observation.pose_index].push_back(
        {MarkerId(static_cast<int>(observation.marker_index)), observation.corners_px});
  }
  std::mt19937 random(9);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (const auto& pose : corridor.truth.keypoints.poses) {
    Vector6d delta;
    for (int c = 0; c < 6; ++c) delta[c] = (c < 3 ? 0.003 : 0.0015) * normal(random);
    corridor.marker_cam_from_world.push_back(Rigid3::Exp(delta) * pose.cam_from_world);
  }
  return corridor;
}

Rigid3 TrueCamFromWorld(const Corridor& corridor, std::size_t pose) {
  return corridor.truth.keypoints.poses[pose].cam_from_world;
}

// The known map: marker 0 alone, fixed.
MarkerMap KnownMap(const Corridor& corridor) {
  MarkerMap map;
  MarkerInfo info;
  info.id = 0;
  info.size = corridor.truth.markers[0].size;
  info.world_from_marker = corridor.truth.markers[0].world_from_marker;
  info.fixed = true;
  map.markers[0] = info;
  return map;
}

// An aligned map: a keyframe at each true pose with the markers it saw.
void AddKeyframes(const Corridor& corridor, Map* map) {
  map->Write([&](MapData& data) {
    for (std::size_t i = 0; i < corridor.markers.size(); ++i) {
      Keyframe keyframe;
      keyframe.timestamp_s = static_cast<double>(i);
      keyframe.camera = corridor.camera;
      keyframe.cam_from_world = TrueCamFromWorld(corridor, i);
      keyframe.markers = corridor.markers[i];
      data.AddKeyframe(std::move(keyframe));
    }
    return 0;
  });
}

// Frame `i` posed by markers alone.
void AddMarkerView(const Corridor& corridor, std::size_t i, OnlineMarkerMapping* mapping) {
  Frame frame;
  frame.timestamp_s = static_cast<double>(i);
  frame.camera = corridor.camera;
  frame.markers = corridor.markers[i];
  MarkerFix fix;
  fix.world_from_cam = corridor.marker_cam_from_world[i].Inverse();
  mapping->AddMarkerView(frame, fix);
}

double WorstPositionError(const MarkerMap& mapped, const Corridor& corridor) {
  double worst = 0.0;
  for (const auto& [id, info] : mapped.markers) {
    worst = std::max(worst, (info.world_from_marker.translation -
                             corridor.truth.markers[id].world_from_marker.translation)
                                .norm());
  }
  return worst;
}

TEST(OnlineMarkerMapping, AlignedKeyframesMapTheUnknownMarkersWhichThenLocateFrames) {
  const Corridor corridor = MakeCorridor();
  Map map;
  AddKeyframes(corridor, &map);
  OnlineMarkerMapping mapping(KnownMap(corridor), {});
  // Not aligned yet: keyframes are not taken.
  mapping.AddKeyframe(map, KeyframeId(0));
  EXPECT_FALSE(mapping.has_mapper());
  ASSERT_TRUE(mapping.Start());
  EXPECT_NE(mapping.landmarks_for_bundle_adjustment(), nullptr);
  const std::vector<KeyframeId> unfed = mapping.UnfedKeyframes(map);
  ASSERT_EQ(unfed.size(), corridor.markers.size());
  for (const KeyframeId& id : unfed) mapping.AddKeyframe(map, id);
  EXPECT_TRUE(mapping.UnfedKeyframes(map).empty());

  const MarkerMap output = mapping.ToMarkerMap();
  ASSERT_EQ(output.markers.size(), corridor.truth.markers.size());
  EXPECT_TRUE(output.markers.at(0).fixed);
  EXPECT_FALSE(output.markers.at(1).fixed);
  // Markers up to 10 m away, 0.1 px corner noise, keyframes at their true poses.
  EXPECT_LT(WorstPositionError(output, corridor), 0.05);
  // Each mapped marker was seen by at least three keyframes: all of them locate frames.
  const std::shared_ptr<const MarkerMap> locating = mapping.LocatingMarkers();
  EXPECT_EQ(locating->markers.size(), corridor.truth.markers.size());
}

TEST(OnlineMarkerMapping, MappedMarkersLocateNothingWithMinLocatingKeyframesZero) {
  const Corridor corridor = MakeCorridor();
  Map map;
  AddKeyframes(corridor, &map);
  OnlineMarkerMappingOptions options;
  options.min_locating_keyframes = 0;
  options.markers_in_local_ba = false;
  OnlineMarkerMapping mapping(KnownMap(corridor), options);
  ASSERT_TRUE(mapping.Start());
  EXPECT_EQ(mapping.landmarks_for_bundle_adjustment(), nullptr);
  EXPECT_NE(mapping.live_landmarks(), nullptr);
  for (const KeyframeId& id : mapping.UnfedKeyframes(map)) mapping.AddKeyframe(map, id);
  EXPECT_EQ(mapping.ToMarkerMap().markers.size(), corridor.truth.markers.size());
  EXPECT_EQ(mapping.LocatingMarkers()->markers.size(), 1u);  // the known map alone locates
}

TEST(OnlineMarkerMapping, MarkerViewsMapMarkersOnlyBeforeTheMapIsLive) {
  const Corridor corridor = MakeCorridor();
  OnlineMarkerMapping before(KnownMap(corridor), {});
  Frame unposed;
  unposed.markers = corridor.markers[0];
  before.AddMarkerView(unposed, std::nullopt);  // no marker location: not a view
  EXPECT_FALSE(before.has_mapper());
  for (std::size_t i = 0; i < corridor.markers.size(); ++i) AddMarkerView(corridor, i, &before);
  // The markers seen with the known one are mapped, and locate frames.
  const MarkerMap mapped = before.ToMarkerMap();
  EXPECT_EQ(mapped.markers.count(1), 1u);
  EXPECT_EQ(mapped.markers.count(2), 1u);
  EXPECT_LT(WorstPositionError(mapped, corridor), 0.05);
  EXPECT_EQ(before.LocatingMarkers()->markers.size(), mapped.markers.size());

  // Once live, the keyframes map markers: frames posed by markers are left out.
  OnlineMarkerMapping live(KnownMap(corridor), {});
  ASSERT_TRUE(live.Start());
  for (std::size_t i = 0; i < corridor.markers.size(); ++i) AddMarkerView(corridor, i, &live);
  EXPECT_EQ(live.ToMarkerMap().markers.size(), 1u);
  // So are they with map_unknown_markers off.
  OnlineMarkerMappingOptions known_only;
  known_only.map_unknown_markers = false;
  OnlineMarkerMapping off(KnownMap(corridor), known_only);
  for (std::size_t i = 0; i < corridor.markers.size(); ++i) AddMarkerView(corridor, i, &off);
  EXPECT_EQ(off.ToMarkerMap().markers.size(), 1u);
}

TEST(OnlineMarkerMapping, AClosedMapFeedsNothingUntilRevivedByAMerge) {
  const Corridor corridor = MakeCorridor();
  Map map;
  AddKeyframes(corridor, &map);
  OnlineMarkerMapping mapping(KnownMap(corridor), {});
  EXPECT_EQ(mapping.CloseMap(), -1);  // no mapper yet
  ASSERT_TRUE(mapping.Start());
  const std::vector<KeyframeId> keyframes = mapping.UnfedKeyframes(map);
  const std::size_t half = keyframes.size() / 2;
  int fed = 0;  // keyframes that saw a marker are recorded
  for (std::size_t i = 0; i < half; ++i) {
    mapping.AddKeyframe(map, keyframes[i]);
    if (!corridor.markers[i].empty()) ++fed;
  }
  ASSERT_GT(fed, 0);
  EXPECT_TRUE(mapping.AdjustsWholeMap());
  const int generation = mapping.CloseMap();
  EXPECT_GE(generation, 0);
  EXPECT_FALSE(mapping.live());
  EXPECT_FALSE(mapping.AdjustsWholeMap());
  EXPECT_EQ(mapping.live_landmarks(), nullptr);
  EXPECT_FALSE(mapping.DecideDriftCorrection(map, WorldAnchoring({}), keyframes[0]).has_value());
  // Every keyframe is unfed again: the closed map's records are retired.
  EXPECT_EQ(mapping.UnfedKeyframes(map).size(), keyframes.size());
  const std::size_t mapped = mapping.ToMarkerMap().markers.size();
  for (std::size_t i = half; i < keyframes.size(); ++i) {
    mapping.AddKeyframe(map, keyframes[i]);
  }
  EXPECT_EQ(mapping.ToMarkerMap().markers.size(), mapped);
  // Merged under new ids (here the same ones): the fed half is live again.
  std::map<KeyframeId, KeyframeId> new_ids;
  for (const KeyframeId& id : keyframes) new_ids[id] = id;
  ASSERT_TRUE(mapping.Start());
  EXPECT_EQ(mapping.ReviveClosedMap(generation, new_ids), fed);
  EXPECT_EQ(mapping.UnfedKeyframes(map).size(), keyframes.size() - static_cast<std::size_t>(fed));
}

TEST(OnlineMarkerMapping, WholeMapAdjustmentPullsAShiftedKeyframeOntoItsMarkers) {
  const Corridor corridor = MakeCorridor();
  Map map;
  AddKeyframes(corridor, &map);
  MarkerMap known = KnownMap(corridor);
  for (std::size_t m = 1; m < corridor.truth.markers.size(); ++m) {
    MarkerInfo info = known.markers.at(0);
    info.id = static_cast<int>(m);
    info.world_from_marker = corridor.truth.markers[m].world_from_marker;
    known.markers[info.id] = info;
  }
  OnlineMarkerMapping mapping(known, {});
  ASSERT_TRUE(mapping.Start());
  const std::vector<KeyframeId> keyframes = mapping.UnfedKeyframes(map);
  for (const KeyframeId& id : keyframes) mapping.AddKeyframe(map, id);
  const KeyframeId shifted = keyframes[5];
  map.Write([&](MapData& data) {
    Rigid3 pose = data.FindKeyframe(shifted)->cam_from_world;
    pose.translation += Eigen::Vector3d(0.1, 0.0, 0.0);
    data.SetKeyframePose(shifted, pose);
    return 0;
  });
  ASSERT_TRUE(mapping.AdjustWholeMap(&map, "test"));
  const double error = map.Read([&](const MapData& data) {
    return (data.FindKeyframe(shifted)->cam_from_world.translation -
            TrueCamFromWorld(corridor, 5).translation)
        .norm();
  });
  EXPECT_LT(error, 0.02);
  EXPECT_EQ(mapping.stats().num_whole_map_adjustments, 1);
}

TEST(OnlineMarkerMapping, CheckNamesTheBadField) {
  std::string why;
  EXPECT_TRUE(OnlineMarkerMappingOptions{}.Check(&why)) << why;
  OnlineMarkerMappingOptions options;
  options.min_locating_keyframes = -1;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("min_locating_keyframes"), std::string::npos) << why;
  options = {};
  options.mapper.min_consistent_views = 1;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("min_consistent_views"), std::string::npos) << why;
}

}  // namespace
}  // namespace arucoslam
