#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>

#include "arucoslam/geometry/umeyama.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/slam/synthetic_marker_scene.h"

namespace arucoslam {
namespace {

using test_scene::kSceneDt;
using test_scene::SceneAbsoluteRmse;
using test_scene::SceneCamera;
using test_scene::SceneDetections;
using test_scene::SceneFrameOf;
using test_scene::SceneMarkers;
using test_scene::SceneWorldFromCam;

struct Scenario {
  // The camera looks past the synthetic cloud's edge after about 120 frames.
  int num_frames = 110;
  int blackout_begin = 30;  // frames [begin, end) have no keypoints and no markers
  int blackout_end = 60;
  bool markers = false;          // a marker map is given
  int markers_until = 1 << 30;   // markers are detected only before this frame
  int markers_again_from = 1 << 30;  // ... and from this frame on
  double marker_size = 0.4;      // m
  bool merge_closed_maps = true;
  bool bridge_tracking_gaps = true;
  bool blocking = true;  // false: local mapping on its own thread
  // From this frame on the keypoints come from another point cloud: the first map never
  // matches again (a loss that no relocalisation ends).
  int scene_changes_at = 1 << 30;
};

struct ScenarioRun {
  std::vector<FrameReport> reports;
  std::vector<StampedPose> trajectory;
  std::vector<StampedPose> keyframes;
  SystemStats stats;
  std::string invariants;
  std::vector<double> map_keyframe_times;  // keyframes of the final map
};

ScenarioRun RunScenario(const Scenario& scenario) {
  const CameraModel camera = SceneCamera();
  SyntheticFeatureScene scene(camera);
  SyntheticFeatureOptions other_cloud;
  other_cloud.seed = 2;
  SyntheticFeatureScene changed_scene(camera, other_cloud);
  SystemOptions options;
  // The synthetic scene gives few keyframes: without this a lost map would be "young" and
  // simply reset, not closed after new_map_after_lost_s.
  options.map_session.reset_max_keyframes = 0;
  options.map_session.merge_closed_maps = scenario.merge_closed_maps;
  options.map_session.bridge_tracking_gaps = scenario.bridge_tracking_gaps;
  options.blocking = scenario.blocking;
  if (scenario.markers) options.marker_map = SceneMarkers(11, scenario.marker_size);
  System system(camera, options);
  std::mt19937 rng(7);
  ScenarioRun run;
  std::vector<int> truth;
  for (int t = 0; t < scenario.num_frames; ++t) {
    const Rigid3 cam_from_world = SceneWorldFromCam(t).Inverse();
    SyntheticFeatureScene& seen = t < scenario.scene_changes_at ? scene : changed_scene;
    Frame frame = seen.MakeFrame(FrameId(t), kSceneDt * t, cam_from_world, &truth);
    std::vector<MarkerDetection> detections;
    if (scenario.markers && (t < scenario.markers_until || t >= scenario.markers_again_from)) {
      detections = SceneDetections(*options.marker_map, camera, cam_from_world, rng);
    }
    if (t >= scenario.blackout_begin && t < scenario.blackout_end) {
      frame.features = OrbFeatures();
      frame.ResetMatches();
      detections.clear();
    }
    run.reports.push_back(system.ProcessFrame(std::move(frame), detections));
  }
  system.Finish();
  run.trajectory = system.Trajectory();
  run.keyframes = system.KeyframePoses();
  run.stats = system.Stats();
  system.map().Read([&](const MapData& data) {
    run.invariants = data.CheckInvariants();
    for (const auto& [id, keyframe] : data.keyframes()) {
      run.map_keyframe_times.push_back(keyframe.timestamp_s);
    }
    return 0;
  });
  return run;
}

// Position RMSE after the best similarity onto the truth, metres.
double Sim3AlignedRmse(const std::vector<StampedPose>& trajectory) {
  std::vector<Eigen::Vector3d> estimated, truth;
  for (const StampedPose& pose : trajectory) {
    estimated.push_back(pose.world_from_cam.translation);
    truth.push_back(SceneWorldFromCam(SceneFrameOf(pose.timestamp_s)).translation);
  }
  const std::optional<Sim3> truth_from_estimate =
      UmeyamaAlignment(estimated, truth, AlignmentKind::kSimilarity);
  if (!truth_from_estimate) return 1e9;
  double sum = 0.0;
  for (std::size_t i = 0; i < estimated.size(); ++i) {
    sum += ((*truth_from_estimate) * estimated[i] - truth[i]).squaredNorm();
  }
  return std::sqrt(sum / estimated.size());
}

TEST(SystemRecovery, KeypointsOnlyStartsANewMapAfterALongLoss) {
  const Scenario scenario;  // 2 s blackout once the first map has many keyframes
  const ScenarioRun run = RunScenario(scenario);
  EXPECT_EQ(run.stats.map_session.num_new_maps_after_loss, 1);
  EXPECT_EQ(run.stats.num_initializations, 2);
  EXPECT_EQ(run.invariants, "");
  // The new map tracks the rest of the route (initialised within half a second).
  for (int t = scenario.blackout_end + 10; t < scenario.num_frames; ++t) {
    EXPECT_TRUE(run.reports[t].cam_from_world.has_value()) << t << ": " << run.reports[t].message;
  }
  // The output is one map's poses (the maps' frames are unrelated): all on one side of the
  // blackout, consistent with the truth up to a similarity (1% of the 1.8 m travelled).
  ASSERT_GT(run.trajectory.size(), 30u);
  const bool first_map = SceneFrameOf(run.trajectory.front().timestamp_s) < scenario.blackout_begin;
  for (const StampedPose& pose : run.trajectory) {
    EXPECT_EQ(SceneFrameOf(pose.timestamp_s) < scenario.blackout_begin, first_map);
  }
  EXPECT_LT(Sim3AlignedRmse(run.trajectory), 0.018);
}

// The frames the first map lost before it was given up get poses from the next map, tracked
// back in time from its initialisation.
TEST(SystemRecovery, FramesLostBeforeANewMapAreTrackedBackFromIt) {
  Scenario scenario;
  scenario.blackout_begin = scenario.blackout_end = 0;
  scenario.scene_changes_at = 30;
  const ScenarioRun run = RunScenario(scenario);
  EXPECT_EQ(run.stats.map_session.num_new_maps_after_loss, 1);
  EXPECT_EQ(run.invariants, "");
  // Lost when they were processed: no pose then.
  int lost = 0;
  for (int t = scenario.scene_changes_at; t < scenario.num_frames; ++t) {
    if (run.reports[t].state == TrackingState::kLost) ++lost;
  }
  EXPECT_GE(lost, 20);  // new_map_after_lost_s at 20 Hz
  // The output is the second map's: every frame from the change on, all consistent with the
  // truth up to a similarity.
  int after_change = 0;
  for (const StampedPose& pose : run.trajectory) {
    EXPECT_GE(SceneFrameOf(pose.timestamp_s), scenario.scene_changes_at);
    ++after_change;
  }
  EXPECT_EQ(after_change, scenario.num_frames - scenario.scene_changes_at);
  EXPECT_LT(Sim3AlignedRmse(run.trajectory), 0.018);
}

TEST(SystemRecovery, NewMapAfterLossIsInitialisedFromMarkersInTheWorld) {
  Scenario scenario;
  scenario.markers = true;
  const ScenarioRun run = RunScenario(scenario);
  EXPECT_EQ(run.stats.map_session.num_new_maps_after_loss, 1);
  // Both maps start from two marker locations, directly in the world.
  EXPECT_EQ(run.stats.num_marker_initializations, 2);
  std::optional<int> second_init;
  for (int t = scenario.blackout_end; t < scenario.num_frames && !second_init; ++t) {
    if (run.reports[t].initialized_map) second_init = t;
  }
  ASSERT_TRUE(second_init.has_value());
  EXPECT_LE(*second_init, scenario.blackout_end + 20);  // 0.5 m of baseline at 0.6 m/s
  const FrameReport& init = run.reports[*second_init];
  EXPECT_TRUE(init.world_aligned) << init.message;
  ASSERT_TRUE(init.cam_from_world.has_value());
  EXPECT_LT((init.cam_from_world->Inverse().translation -
             SceneWorldFromCam(*second_init).translation).norm(), 0.015);  // measured 4 mm
  // Every frame outside the blackout has a world pose (marker poses until the map starts);
  // absolute error, no alignment (markers alone: about 15 mm).
  EXPECT_EQ(static_cast<int>(run.trajectory.size()),
            scenario.num_frames - (scenario.blackout_end - scenario.blackout_begin));
  EXPECT_LT(SceneAbsoluteRmse(run.trajectory), 0.02);
  EXPECT_EQ(run.invariants, "");
}

int CountBefore(const std::vector<double>& times, double limit_s) {
  return static_cast<int>(std::count_if(times.begin(), times.end(),
                                        [&](double t) { return t < limit_s; }));
}

// Once the second map is in the world, the first one (closed at the loss) joins it: one map
// holds both sides of the blackout, each keyframe is output once, the poses stay as accurate.
TEST(SystemRecovery, ClosedMapIsMergedIntoTheNextMapInTheWorld) {
  Scenario scenario;
  scenario.markers = true;
  const ScenarioRun merged = RunScenario(scenario);
  scenario.merge_closed_maps = false;
  const ScenarioRun apart = RunScenario(scenario);
  const double blackout_s = kSceneDt * scenario.blackout_begin;
  EXPECT_EQ(merged.stats.map_session.num_map_merges, 1);
  EXPECT_EQ(apart.stats.map_session.num_map_merges, 0);
  EXPECT_EQ(merged.invariants, "");
  // Apart: the final map starts after the blackout; merged: it holds the first map too.
  EXPECT_EQ(CountBefore(apart.map_keyframe_times, blackout_s), 0);
  const int first_map_keyframes = CountBefore(merged.map_keyframe_times, blackout_s);
  EXPECT_GE(first_map_keyframes, 3);
  EXPECT_GT(static_cast<int>(merged.map_keyframe_times.size()), first_map_keyframes);
  // The output lists each keyframe once: the closed map's are no longer listed apart.
  EXPECT_EQ(merged.keyframes.size(), merged.map_keyframe_times.size());
  std::vector<double> output_times;
  for (const StampedPose& pose : merged.keyframes) output_times.push_back(pose.timestamp_s);
  EXPECT_EQ(CountBefore(output_times, blackout_s), first_map_keyframes);
  // In time order (keyframes.tum): the merged map's keyframes are numbered after the new
  // map's, and `eval` refuses a file whose time goes back.
  EXPECT_TRUE(std::is_sorted(output_times.begin(), output_times.end()));
  EXPECT_EQ(merged.trajectory.size(), apart.trajectory.size());
  EXPECT_LT(SceneAbsoluteRmse(merged.trajectory), 0.02);
  std::printf("first map: %d keyframes merged; world RMSE merged %.4f m, apart %.4f m\n",
              first_map_keyframes, SceneAbsoluteRmse(merged.trajectory),
              SceneAbsoluteRmse(apart.trajectory));
}

// Position RMSE of the poses in frames [begin, end), no alignment, metres.
double WindowRmse(const std::vector<StampedPose>& trajectory, int begin, int end, int* count) {
  std::vector<StampedPose> window;
  for (const StampedPose& pose : trajectory) {
    const int t = SceneFrameOf(pose.timestamp_s);
    if (t >= begin && t < end) window.push_back(pose);
  }
  *count = static_cast<int>(window.size());
  return SceneAbsoluteRmse(window);
}

// A map started after a loss with no marker in view is put in the world by the markers it
// meets later; once it has absorbed the closed map, the closed map's motion before the gap
// ties its start too (the bridge) in a pose-graph correction. Here the keypoints alone keep
// the new map right (the end-of-run adjustment restores it even from a bridge 0.5 m off):
// the bridge must leave it so. Where it helps (a young map drifting in a low-texture turn):
// the demo sequence, figures at MapSessionOptions::bridge_tracking_gaps.
TEST(SystemRecovery, MapAfterAGapIsBridgedToTheClosedMap) {
  Scenario scenario;
  scenario.markers = true;
  scenario.markers_until = scenario.blackout_begin;
  scenario.markers_again_from = 85;
  const ScenarioRun bridged = RunScenario(scenario);
  scenario.bridge_tracking_gaps = false;
  const ScenarioRun unbridged = RunScenario(scenario);
  EXPECT_EQ(bridged.stats.map_session.num_map_merges, 1);
  EXPECT_EQ(bridged.stats.map_session.num_bridged_gaps, 1);
  EXPECT_EQ(unbridged.stats.map_session.num_bridged_gaps, 0);
  EXPECT_EQ(bridged.invariants, "");
  int bridged_count = 0, unbridged_count = 0;
  const double bridged_rmse = WindowRmse(bridged.trajectory, scenario.blackout_end,
                                         scenario.markers_again_from, &bridged_count);
  const double unbridged_rmse = WindowRmse(unbridged.trajectory, scenario.blackout_end,
                                           scenario.markers_again_from, &unbridged_count);
  std::printf(
      "frames between the gap and the markers: bridged %d poses %.4f m, unbridged %d "
      "poses %.4f m; whole run %.4f / %.4f m\n",
      bridged_count, bridged_rmse, unbridged_count, unbridged_rmse,
      SceneAbsoluteRmse(bridged.trajectory), SceneAbsoluteRmse(unbridged.trajectory));
  // Measured 25 poses, 4.3 mm both; whole run 9.7 / 9.6 mm.
  EXPECT_EQ(bridged_count, scenario.markers_again_from - scenario.blackout_end);
  EXPECT_LT(bridged_rmse, 0.01);
  EXPECT_LT(bridged_rmse, unbridged_rmse + 0.002);
  EXPECT_LT(SceneAbsoluteRmse(bridged.trajectory), 0.02);
}

// The same with local mapping on its own thread: the merge stops and restarts it.
TEST(SystemRecovery, ClosedMapIsMergedWithLocalMappingThreaded) {
  Scenario scenario;
  scenario.markers = true;
  scenario.blocking = false;
  const ScenarioRun run = RunScenario(scenario);
  EXPECT_EQ(run.stats.map_session.num_map_merges, 1);
  EXPECT_EQ(run.invariants, "");
  EXPECT_GE(CountBefore(run.map_keyframe_times, kSceneDt * scenario.blackout_begin), 3);
  EXPECT_EQ(run.keyframes.size(), run.map_keyframe_times.size());
  EXPECT_LT(SceneAbsoluteRmse(run.trajectory), 0.02);
}

TEST(SystemRecovery, MapNeverAlignedStaysOutOfTheWorldTrajectory) {
  Scenario scenario;
  scenario.markers = true;
  scenario.markers_until = scenario.blackout_begin;  // no marker after the blackout
  const ScenarioRun run = RunScenario(scenario);
  EXPECT_EQ(run.stats.map_session.num_new_maps_after_loss, 1);
  EXPECT_EQ(run.stats.num_initializations, 2);  // the second map is built and tracked ...
  EXPECT_FALSE(run.reports.back().world_aligned);
  EXPECT_TRUE(run.reports.back().cam_from_world.has_value());
  // ... but its poses and keyframes are not in the world frame and are not output.
  for (const StampedPose& pose : run.trajectory) {
    EXPECT_LT(SceneFrameOf(pose.timestamp_s), scenario.blackout_begin);
  }
  for (const StampedPose& keyframe : run.keyframes) {
    EXPECT_LT(SceneFrameOf(keyframe.timestamp_s), scenario.blackout_begin);
  }
  EXPECT_GE(static_cast<int>(run.trajectory.size()), scenario.blackout_begin);
  EXPECT_FALSE(run.keyframes.empty());  // the closed aligned map's keyframes are kept
  EXPECT_LT(SceneAbsoluteRmse(run.trajectory), 0.02);
}

TEST(SystemRecovery, FarMarkersGiveNoLocation) {
  Scenario scenario;
  scenario.num_frames = 30;
  scenario.blackout_begin = scenario.blackout_end = 0;
  scenario.markers = true;
  scenario.marker_size = 0.1;  // 3 m away: 30 sides, beyond max_marker_distance_sides (25)
  const ScenarioRun far = RunScenario(scenario);
  EXPECT_EQ(far.stats.marker_fusion.num_located_frames, 0);
  EXPECT_TRUE(far.trajectory.empty());  // the keypoint map is never put in the world
  scenario.marker_size = 0.2;  // 15 sides
  const ScenarioRun near = RunScenario(scenario);
  EXPECT_GT(near.stats.marker_fusion.num_located_frames, 20);
}

}  // namespace
}  // namespace arucoslam
