#include "arucoslam/slam/frame_flow.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "arucoslam/geometry/umeyama.h"
#include "arucoslam/slam/synthetic_features.h"
#include "arucoslam/slam/flow_test_doubles.h"
#include "arucoslam/slam/synthetic_marker_scene.h"

namespace arucoslam {
namespace {

using test_doubles::InlineMapping;
using test_doubles::ScriptedPlaces;
using test_scene::kSceneDt;
using test_scene::SceneCamera;
using test_scene::SceneDetections;
using test_scene::SceneMarkers;
using test_scene::SceneWorldFromCam;

// A FrameFlow, without places unless given, fed frames of the synthetic scene; with `markers` it knows the
// scene's wall of markers and locates each frame from their detections first.
class FlowHarness {
 public:
  explicit FlowHarness(bool markers) : FlowHarness(markers, Options(markers)) {}
  // `places` serves the first map only.
  FlowHarness(bool markers, const FrameFlowOptions& options,
              std::unique_ptr<PlaceIndex> places = nullptr)
      : flow_(SceneCamera(), options, &mapping_,
              [held = std::make_shared<std::unique_ptr<PlaceIndex>>(std::move(places))](Map&) {
                return std::move(*held);
              },
              &stats_, &mutex_),
        markers_(markers) {}

  static FrameFlowOptions Options(bool markers) {
    FrameFlowOptions options;
    if (markers) options.marker_map = SceneMarkers();
    options.keyframes.min_frames_between = 0;
    return options;
  }

  // Frame at time t and route position t - route_shift, with its keypoints (and markers)
  // unless `blank`.
  FrameReport Step(int t, bool blank = false, int route_shift = 0) {
    const Rigid3 cam_from_world = SceneWorldFromCam(t - route_shift).Inverse();
    Frame frame = scene_.MakeFrame(FrameId(index_), kSceneDt * t, cam_from_world, &truth_);
    std::vector<MarkerDetection> detections;
    if (markers_ && !blank) {
      detections = SceneDetections(SceneMarkers(), SceneCamera(), cam_from_world, rng_);
    }
    if (blank) {
      frame.features = OrbFeatures();
      frame.ResetMatches();
    }
    FrameReport report;
    report.index = index_++;
    report.timestamp_s = frame.timestamp_s;
    if (markers_) {
      for (const MarkerDetection& detection : detections) {
        frame.markers.push_back({MarkerId(detection.id), detection.corners});
      }
      flow_.marker_mapping().AdoptWorldOrigin(detections, frame.camera);
      flow_.marker_fusion().Locate(detections, *flow_.marker_mapping().LocatingMarkers(),
                                   frame.timestamp_s, flow_.Prediction(frame.timestamp_s),
                                   report.index);
    }
    flow_.Process(frame, report);
    for (const KeyframeId keyframe : mapping_.pending) flow_.MapKeyframe(keyframe);
    mapping_.pending.clear();
    return report;
  }

  FrameFlow& flow() { return flow_; }
  const FrameFlowStats& stats() const { return stats_; }
  InlineMapping& mapping() { return mapping_; }

 private:
  InlineMapping mapping_;
  FrameFlowStats stats_;
  std::mutex mutex_;
  FrameFlow flow_;
  bool markers_;
  SyntheticFeatureScene scene_{SceneCamera()};
  std::mt19937 rng_{7};
  std::vector<int> truth_;
  std::size_t index_ = 0;
};

Eigen::Vector3d TruePosition(const StampedPose& pose) {
  return SceneWorldFromCam(test_scene::SceneFrameOf(pose.timestamp_s)).translation;
}

// RMS position error after mapping the estimates by `truth_from_estimate`, metres.
double RmsError(const std::vector<StampedPose>& poses, const Sim3& truth_from_estimate) {
  double sum = 0.0;
  for (const StampedPose& pose : poses) {
    sum += (truth_from_estimate * pose.world_from_cam.translation - TruePosition(pose))
               .squaredNorm();
  }
  return poses.empty() ? 1e9 : std::sqrt(sum / poses.size());
}

// The similarity that best maps the estimated positions onto the truth.
Sim3 TruthFromEstimate(const std::vector<StampedPose>& poses) {
  std::vector<Eigen::Vector3d> estimated, truth;
  for (const StampedPose& pose : poses) {
    estimated.push_back(pose.world_from_cam.translation);
    truth.push_back(TruePosition(pose));
  }
  const std::optional<Sim3> alignment =
      UmeyamaAlignment(estimated, truth, AlignmentKind::kSimilarity);
  EXPECT_TRUE(alignment.has_value());
  return alignment.value_or(Sim3());
}

TEST(FrameFlow, RefusesInvalidOptionsNamingTheField) {
  FrameFlowOptions options = FlowHarness::Options(/*markers=*/true);
  options.tracker.min_reference_matches = -1;
  try {
    FlowHarness harness(/*markers=*/true, options);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(),
                 "FrameFlowOptions: tracker.min_reference_matches must be >= 0, is -1");
  }
}

TEST(FrameFlow, KeypointsAloneInitialiseTrackAndMapTheSceneUpToScale) {
  FlowHarness harness(/*markers=*/false);
  int first_initialised = -1;
  const int num_frames = 80;
  for (int t = 0; t < num_frames; ++t) {
    const FrameReport report = harness.Step(t);
    if (report.initialized_map && first_initialised < 0) first_initialised = t;
    if (first_initialised >= 0) EXPECT_EQ(report.state, TrackingState::kTracking) << t;
  }
  harness.flow().Finish();
  ASSERT_GE(first_initialised, 1);
  EXPECT_LE(first_initialised, 10);
  EXPECT_EQ(harness.stats().num_initializations, 1);
  EXPECT_EQ(harness.stats().num_losses, 0);
  EXPECT_GE(harness.stats().num_keyframes_inserted, 3);
  EXPECT_FALSE(harness.flow().world_aligned());
  // Nothing moved the map as a whole: mapping was never paused or held.
  EXPECT_EQ(harness.mapping().num_pauses, 0);
  EXPECT_EQ(harness.mapping().num_holds, 0);
  const std::vector<StampedPose> trajectory = harness.flow().CheckedTrajectory(nullptr);
  EXPECT_GE(static_cast<int>(trajectory.size()), 0.95 * (num_frames - first_initialised));
  // The camera travels about 2.4 m; the bound is 1% of that.
  EXPECT_LT(RmsError(trajectory, TruthFromEstimate(trajectory)), 0.024);
}

TEST(FrameFlow, ALiveSourcesYoungMapTakesNoKeyframeWhileTheMapperIsBusy) {
  // A busy mapper: a recorded sequence's young map still takes a keyframe after
  // max_frames_between frames (tracking would then wait for it to be mapped); a live
  // source's, which never waits, takes one only once the mapper is idle.
  for (const bool live : {false, true}) {
    SCOPED_TRACE(live ? "live" : "recorded");
    FrameFlowOptions options = FlowHarness::Options(/*markers=*/false);
    options.synchronous_young_map_keyframes = 1000;
    options.live_source = live;
    FlowHarness harness(/*markers=*/false, options);
    int t = 0;
    for (; t < 30; ++t) harness.Step(t);
    ASSERT_EQ(harness.flow().state(), TrackingState::kTracking);
    harness.mapping().busy = true;
    int inserted_while_busy = 0;
    for (const int end = t + 30; t < end; ++t) {
      const FrameReport report = harness.Step(t);
      EXPECT_EQ(report.state, TrackingState::kTracking) << t;
      if (report.new_keyframe) ++inserted_while_busy;
    }
    if (live) {
      EXPECT_EQ(inserted_while_busy, 0);
    } else {
      EXPECT_GE(inserted_while_busy, 1);
    }
    harness.mapping().busy = false;
    bool inserted_when_idle = false;
    for (const int end = t + 30; t < end; ++t) inserted_when_idle |= harness.Step(t).new_keyframe;
    EXPECT_TRUE(inserted_when_idle);
  }
}

TEST(FrameFlow, KnownMarkersPutTheMapInTheWorldAtMetricScale) {
  FlowHarness harness(/*markers=*/true);
  std::vector<FrameReport> reports;
  for (int t = 0; t < 80; ++t) reports.push_back(harness.Step(t));
  harness.flow().Finish();
  EXPECT_TRUE(harness.flow().world_aligned());
  EXPECT_EQ(harness.stats().num_marker_initializations, 1);
  // Before the map exists the markers alone give the pose.
  EXPECT_TRUE(reports.front().marker_pose);
  EXPECT_GT(harness.stats().num_marker_only_poses, 0);
  EXPECT_FALSE(reports.back().marker_pose);
  EXPECT_TRUE(reports.back().world_aligned);
  ASSERT_TRUE(reports.back().online_world_from_cam);
  // Each alignment held mapping while it moved the map, and released it.
  EXPECT_GE(harness.mapping().num_holds, 1);
  EXPECT_EQ(harness.mapping().num_holds, harness.mapping().num_releases);
  const std::vector<StampedPose> trajectory = harness.flow().CheckedTrajectory(nullptr);
  EXPECT_EQ(trajectory.size(), 80u);
  // In the world frame as it is, without alignment: a centimetre.
  EXPECT_LT(RmsError(trajectory, Sim3()), 0.01);
  EXPECT_NEAR(TruthFromEstimate(trajectory).scale, 1.0, 0.01);
}

TEST(FrameFlow, LoadedMapRefusesABlankFrameThenLocalisesWithoutChangingTheMap) {
  FlowHarness builder(/*markers=*/false);
  for (int t = 0; t < 60; ++t) builder.Step(t);
  builder.flow().Finish();
  const Sim3 truth_from_map = TruthFromEstimate(builder.flow().CheckedTrajectory(nullptr));
  MapData saved = builder.flow().map().Read([](const MapData& data) { return data; });
  const std::size_t num_keyframes = saved.NumKeyframes();

  FlowHarness harness(/*markers=*/false);
  harness.flow().StartFromMap(std::move(saved), /*world_aligned=*/false,
                              /*localize_only=*/true);
  const FrameReport blank = harness.Step(30, /*blank=*/true);
  EXPECT_EQ(blank.state, TrackingState::kNotInitialized);
  EXPECT_EQ(blank.message, "not localised in the loaded map");
  EXPECT_FALSE(blank.cam_from_world);
  const FrameReport first = harness.Step(30);
  EXPECT_EQ(first.state, TrackingState::kTracking);
  EXPECT_EQ(first.message, "relocalised in the loaded map");
  for (int t = 31; t < 50; ++t) EXPECT_EQ(harness.Step(t).state, TrackingState::kTracking);
  harness.flow().Finish();
  EXPECT_EQ(harness.stats().num_map_relocalizations, 1);
  EXPECT_EQ(harness.stats().num_keyframes_inserted, 0);
  EXPECT_EQ(harness.flow().map().NumKeyframes(), num_keyframes);
  const std::vector<StampedPose> trajectory = harness.flow().CheckedTrajectory(nullptr);
  EXPECT_EQ(trajectory.size(), 20u);
  // In the loaded map's frame: the first pass's similarity puts them on the truth.
  EXPECT_LT(RmsError(trajectory, truth_from_map), 0.02);
}

TEST(FrameFlow, ALongLossStartsANewMapThatInitialisesAgain) {
  FrameFlowOptions options = FlowHarness::Options(/*markers=*/false);
  options.map_session.reset_max_keyframes = 2;  // the map is not young: kept while lost
  FlowHarness harness(/*markers=*/false, options);
  for (int t = 0; t < 40; ++t) harness.Step(t);
  ASSERT_EQ(harness.stats().num_initializations, 1);
  EXPECT_EQ(harness.mapping().num_pauses, 0);
  const std::size_t num_keyframes = harness.flow().map().NumKeyframes();
  ASSERT_GT(num_keyframes, 2u);
  // 1.5 s without keypoints: longer than new_map_after_lost_s (1 s).
  std::vector<FrameReport> blackout;
  int pauses_within_a_second = -1;
  for (int t = 40; t < 70; ++t) {
    blackout.push_back(harness.Step(t, /*blank=*/true));
    if (t == 58) pauses_within_a_second = harness.mapping().num_pauses;
  }
  EXPECT_EQ(blackout.front().state, TrackingState::kLost);
  EXPECT_EQ(blackout.front().message, "tracking lost");
  // Lost for less than a second: the map is kept for a relocalisation.
  EXPECT_EQ(blackout[18].state, TrackingState::kLost);
  EXPECT_EQ(pauses_within_a_second, 0);
  EXPECT_EQ(blackout.back().state, TrackingState::kNotInitialized);
  EXPECT_EQ(harness.flow().map_session().stats().num_new_maps_after_loss, 1);
  EXPECT_EQ(harness.flow().map().NumKeyframes(), 0u);
  // The reset paused mapping while the map was replaced.
  EXPECT_EQ(harness.mapping().num_pauses, 1);
  EXPECT_EQ(harness.mapping().num_resumes, 1);
  int reinitialised = -1;
  for (int t = 70; t < 110 && reinitialised < 0; ++t) {
    if (harness.Step(t).initialized_map) reinitialised = t;
  }
  EXPECT_GE(reinitialised, 71);
  EXPECT_LE(reinitialised, 80);
  EXPECT_EQ(harness.stats().num_initializations, 2);
  EXPECT_EQ(harness.stats().num_losses, 1);
}

TEST(FrameFlow, APlacePoseIsTakenOnlyWhenTheLocalMapConfirmsIt) {
  // Without the reference-keyframe fallback the frame after the initialisation (no motion
  // known yet) is lost, and only the place database can give its pose back.
  FrameFlowOptions options = FlowHarness::Options(/*markers=*/false);
  options.tracker.min_reference_matches = 1000000;
  options.map_session.reset_max_keyframes = 0;  // the young map is kept while lost
  auto owned = std::make_unique<ScriptedPlaces>();
  ScriptedPlaces* places = owned.get();
  FlowHarness harness(/*markers=*/false, options, std::move(owned));
  int t = 0;
  FrameReport initialised;
  for (; t < 10 && !initialised.initialized_map; ++t) initialised = harness.Step(t);
  ASSERT_TRUE(initialised.initialized_map);
  ASSERT_TRUE(initialised.cam_from_world);
  EXPECT_EQ(places->num_mapped, 2);  // both initial keyframes
  const int t_second = t - 1;
  const Rigid3 second_pose = *initialised.cam_from_world;
  const std::vector<StampedPose> keyframes = harness.flow().KeyframePoses();
  ASSERT_EQ(keyframes.size(), 2u);
  const int t_first = test_scene::SceneFrameOf(keyframes.front().timestamp_s);
  const Eigen::Vector3d first_centre = keyframes.front().world_from_cam.translation;
  const Eigen::Vector3d second_centre = second_pose.Inverse().translation;
  const double baseline = (second_centre - first_centre).norm();

  // The second keyframe's pose moved sideways by ten baselines: refined against the local
  // map it finds no support and is refused; the map is kept.
  RelocalizationResult far;
  far.cam_from_world =
      Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(10.0 * baseline, 0.0, 0.0)) *
      second_pose;
  far.keyframe = harness.flow().map().Read(
      [](const MapData& data) { return data.keyframes().rbegin()->first; });
  places->offer = far;
  const FrameReport refused = harness.Step(t++);
  EXPECT_EQ(refused.state, TrackingState::kLost);
  EXPECT_EQ(refused.message, "tracking lost");
  EXPECT_EQ(places->num_queries, 1);
  EXPECT_EQ(places->num_taken, 0);
  EXPECT_EQ(harness.flow().map().NumKeyframes(), 2u);

  // The second keyframe's pose as it is, two frames behind the camera: refined and taken.
  RelocalizationResult near = far;
  near.cam_from_world = second_pose;
  places->offer = near;
  const int t_taken = t;
  const FrameReport taken = harness.Step(t++);
  EXPECT_EQ(taken.state, TrackingState::kTracking);
  EXPECT_EQ(taken.message, "relocalised from the place database");
  EXPECT_EQ(places->num_taken, 1);
  ASSERT_TRUE(taken.cam_from_world);
  // The refined pose moved on from the second keyframe as the camera did: the step relative
  // to the baseline (scale-free) within 10% and its direction within 5 degrees.
  const auto position = [](int frame) { return SceneWorldFromCam(frame).translation; };
  const Eigen::Vector3d true_step = position(t_taken) - position(t_second);
  const Eigen::Vector3d true_baseline = position(t_second) - position(t_first);
  const Eigen::Vector3d step = taken.cam_from_world->Inverse().translation - second_centre;
  const double true_ratio = true_step.norm() / true_baseline.norm();
  EXPECT_NEAR(step.norm() / baseline, true_ratio, 0.1 * true_ratio);
  const auto angle_deg = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
  };
  EXPECT_NEAR(angle_deg(step, second_centre - first_centre),
              angle_deg(true_step, true_baseline), 5.0);
}

}  // namespace
}  // namespace arucoslam
