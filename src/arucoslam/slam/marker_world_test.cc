// MarkerWorld on a map of keyframes along a circular route (synthetic_route_map.h) moved out of
// the world by a known similarity, and on frames of the marker wall scene
// (synthetic_marker_scene.h): the alignment waits for enough anchors, then puts the map and
// the current frame back in the world; a marker location gives a marker-only pose.
#include "arucoslam/slam/marker_world.h"

#include <gtest/gtest.h>

#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <vector>

#include "arucoslam/slam/flow_test_doubles.h"
#include "arucoslam/slam/synthetic_marker_scene.h"
#include "arucoslam/slam/synthetic_route_map.h"
#include "arucoslam/slam/world_alignment.h"

namespace arucoslam {
namespace {

using test_doubles::InlineMapping;

// The objects FrameFlow lends the marker world, for a run with the scene's markers and
// without places.
class MarkerWorldHarness {
 public:
  MarkerWorldHarness()
      : pose_history_(/*keep_matches=*/false, [](KeyframeId) { return 1.0; }),
        marker_fusion_(options_.marker_fusion, test_scene::SceneCamera(),
                       test_scene::SceneMarkers(), 0.0),
        anchoring_(options_.world_anchoring),
        marker_mapping_(options_.marker_map, options_.marker_mapping),
        lifecycle_(
            options_, [](Map&) { return std::unique_ptr<PlaceIndex>(); }, &stats_, &stats_mutex_),
        world_(options_, &stats_, &stats_mutex_) {}

  MarkerWorldParts Parts() {
    return {map_,           tracker_,        mapper_,    pose_history_, anchoring_,
            marker_fusion_, marker_mapping_, lifecycle_, mapping_};
  }

  MarkerWorld& world() { return world_; }
  Map& map() { return map_; }
  WorldAnchoring& anchoring() { return anchoring_; }
  MarkerFusion& marker_fusion() { return marker_fusion_; }
  const PoseHistory& pose_history() const { return pose_history_; }
  const InlineMapping& mapping() const { return mapping_; }
  const FrameFlowStats& stats() const { return stats_; }

 private:
  FrameFlowOptions options_ = [] {
    FrameFlowOptions options;
    options.marker_map = test_scene::SceneMarkers();
    return options;
  }();
  FrameFlowStats stats_;
  std::mutex stats_mutex_;
  InlineMapping mapping_;
  Map map_;
  Tracker tracker_{map_, options_.tracker};
  LocalMapper mapper_{map_, options_.mapper};
  PoseHistory pose_history_;
  MarkerFusion marker_fusion_;
  WorldAnchoring anchoring_;
  OnlineMarkerMapping marker_mapping_;
  MapLifecycle lifecycle_;
  MarkerWorld world_;
};

MarkerFix FixAt(const Rigid3& cam_from_world) {
  MarkerFix fix;
  fix.world_from_cam = cam_from_world.Inverse();
  return fix;
}

Eigen::Vector3d CentreOf(const Map& map, KeyframeId keyframe) {
  return map.Read([&](const MapData& data) {
    return data.FindKeyframe(keyframe)->cam_from_world.Inverse().translation;
  });
}

TEST(MarkerWorld, TheMapIsAlignedOnceEnoughAnchorsAgreeAndTheFrameFollows) {
  MarkerWorldHarness harness;
  SyntheticRoute route;
  std::vector<Rigid3> truth;
  for (const double azimuth : {0.0, 3.0, 6.0, 9.0, 12.0}) {
    truth.push_back(route.CamFromWorld(azimuth));
  }
  const std::vector<KeyframeId> ids = route.AddRoute(truth, &harness.map());
  // The map at half scale, turned and shifted: what a monocular map starts as.
  const Sim3 world_from_map(2.0,
                            Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ())),
                            Eigen::Vector3d(0.3, -0.2, 1.0));
  harness.map().Write([&](MapData& data) { ApplyWorldAlignment(world_from_map.Inverse(), &data); });
  Frame frame;
  frame.timestamp_s = 1.0;
  frame.cam_from_world = harness.map().Read(
      [&](const MapData& data) { return data.FindKeyframe(ids.back())->cam_from_world; });
  ASSERT_GT((CentreOf(harness.map(), ids[0]) - truth[0].Inverse().translation).norm(), 0.5);

  // Three anchors: fewer than min_alignment_anchors (4); nothing moves.
  for (int i = 0; i < 3; ++i) harness.anchoring().AddAnchor(ids[i], FixAt(truth[i]));
  harness.world().MaybeAlign(harness.Parts(), frame);
  EXPECT_FALSE(harness.anchoring().aligned());
  EXPECT_EQ(harness.mapping().num_holds, 0);

  for (int i = 3; i < 5; ++i) harness.anchoring().AddAnchor(ids[i], FixAt(truth[i]));
  harness.world().MaybeAlign(harness.Parts(), frame);
  EXPECT_TRUE(harness.anchoring().aligned());
  // Mapping held (not drained) while the map moved, and released.
  EXPECT_EQ(harness.mapping().num_holds, 1);
  EXPECT_EQ(harness.mapping().num_releases, 1);
  EXPECT_EQ(harness.mapping().num_pauses, 0);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    EXPECT_LT((CentreOf(harness.map(), ids[i]) - truth[i].Inverse().translation).norm(), 1e-6) << i;
  }
  ASSERT_TRUE(frame.cam_from_world);
  EXPECT_LT(
      (frame.cam_from_world->Inverse().translation - truth.back().Inverse().translation).norm(),
      1e-6);
}

TEST(MarkerWorld, AMarkerLocationGivesAPoseButNoRelocalisationOutsideTheWorld) {
  MarkerWorldHarness harness;
  const int t = 10;
  const Rigid3 cam_from_world = test_scene::SceneWorldFromCam(t).Inverse();
  std::mt19937 rng(3);
  const std::vector<MarkerDetection> detections = test_scene::SceneDetections(
      test_scene::SceneMarkers(), test_scene::SceneCamera(), cam_from_world, rng);
  ASSERT_GE(detections.size(), 3u);
  harness.marker_fusion().Locate(detections, test_scene::SceneMarkers(), test_scene::kSceneDt * t,
                                 MapPrediction(), 0);
  ASSERT_TRUE(harness.marker_fusion().fix());
  Frame frame;
  frame.timestamp_s = test_scene::kSceneDt * t;
  FrameReport report;
  // The map is not in the world: its tracker is not restarted from the marker pose.
  EXPECT_FALSE(harness.world().Relocalize(harness.Parts(), frame, report));
  EXPECT_TRUE(report.message.empty());
  EXPECT_EQ(harness.stats().num_marker_relocalizations, 0);

  harness.world().RecordMarkerPose(harness.Parts(), frame, report);
  EXPECT_TRUE(report.marker_pose);
  ASSERT_TRUE(report.cam_from_world);
  // Corner noise of 0.3 px at 3 m: within a centimetre.
  EXPECT_LT(
      (report.cam_from_world->Inverse().translation - cam_from_world.Inverse().translation).norm(),
      0.01);
  EXPECT_EQ(harness.stats().num_marker_only_poses, 1);
  ASSERT_EQ(harness.pose_history().poses().size(), 1u);
  EXPECT_TRUE(harness.pose_history().poses().front().in_world);
}

}  // namespace
}  // namespace arucoslam
