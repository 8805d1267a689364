// MapSession's bridge over a tracking gap: the closed map's last second of motion predicts the
// next map's first keyframe, with sigmas growing with the gap, and the merged map is corrected
// towards that prediction by the pose graph.
#include <gtest/gtest.h>

#include <vector>

#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/synthetic_route_map.h"

namespace arucoslam {
namespace {

// The closed map's camera poses over its last second (10 Hz), moving at `velocity` (m/s, world)
// from `start` (world_from_cam).
ClosingWorldMap ClosingAfterMotion(const Rigid3& start, const Eigen::Vector3d& velocity) {
  ClosingWorldMap closing;
  for (int i = 0; i <= 10; ++i) {
    const double t = 0.1 * i;
    closing.motion_poses.push_back({t, Rigid3(start.rotation, start.translation + t * velocity)});
  }
  return closing;
}

// A session whose world-aligned map closed after ClosingAfterMotion (last pose at t = 1 s),
// waiting for the next map.
void CloseAfterMotion(MapSession& session, const Rigid3& start, const Eigen::Vector3d& velocity) {
  const Map closed;
  session.CloseWorldMap(closed, ClosingAfterMotion(start, velocity));
  session.StartNewMap(0);
}

double InverseSquare(double sigma) { return 1.0 / (sigma * sigma); }

TEST(MapSessionBridge, PriorSigmasGrowWithTheGap) {
  MapSession session({}, /*marker_world=*/true);
  CloseAfterMotion(session, Rigid3(), Eigen::Vector3d(0.5, 0.0, 0.0));
  session.AddBridgePrior(KeyframeId(1), 1.5, /*world_aligned=*/false);  // gap 0.5 s
  session.AddBridgePrior(KeyframeId(2), 3.0, /*world_aligned=*/false);  // gap 2 s
  ASSERT_EQ(session.bridge_priors().size(), 2u);
  const KeyframePosePrior& near = session.bridge_priors()[0];
  const KeyframePosePrior& far = session.bridge_priors()[1];
  EXPECT_EQ(near.keyframe, KeyframeId(1));
  EXPECT_NEAR(near.world_from_cam.translation.x(), 0.75, 1e-9);  // constant velocity
  EXPECT_NEAR(far.world_from_cam.translation.x(), 1.5, 1e-9);
  // Position: 0.025 m + 0.1 m/s x gap; rotation: 0.05 rad + 0.5 rad/s x gap.
  EXPECT_NEAR(near.information(0, 0), InverseSquare(0.075), 1e-6);
  EXPECT_NEAR(near.information(3, 3), InverseSquare(0.3), 1e-9);
  EXPECT_NEAR(far.information(2, 2), InverseSquare(0.225), 1e-6);
  EXPECT_NEAR(far.information(5, 5), InverseSquare(1.05), 1e-9);
  // In the bundle adjustments: 0.025 m + 0.3 m/s^2 x gap^2 / 2, the rotation as above.
  ASSERT_EQ(session.bridge_adjustment_priors().size(), 2u);
  EXPECT_NEAR(session.bridge_adjustment_priors()[0].information(0, 0), InverseSquare(0.0625), 1e-6);
  EXPECT_NEAR(session.bridge_adjustment_priors()[1].information(1, 1), InverseSquare(0.625), 1e-9);
  EXPECT_NEAR(session.bridge_adjustment_priors()[1].information(4, 4), InverseSquare(1.05), 1e-9);
}

TEST(MapSessionBridge, NoPriorWithoutAClosedMapNorAfterTooLongAGapNorInTheWorld) {
  const Eigen::Vector3d velocity(0.5, 0.0, 0.0);
  MapSession nothing_closed({}, true);
  nothing_closed.AddBridgePrior(KeyframeId(1), 1.5, false);
  EXPECT_FALSE(nothing_closed.HasBridgePriors());

  MapSession session({}, true);
  CloseAfterMotion(session, Rigid3(), velocity);
  session.AddBridgePrior(KeyframeId(1), 4.5, false);  // 3.5 s after: beyond max_age_s 3
  session.AddBridgePrior(KeyframeId(2), 1.5, /*world_aligned=*/true);
  EXPECT_FALSE(session.HasBridgePriors());

  MapSessionOptions off;
  off.bridge_tracking_gaps = false;
  MapSession unbridged(off, true);
  CloseAfterMotion(unbridged, Rigid3(), velocity);
  unbridged.AddBridgePrior(KeyframeId(1), 1.5, false);
  EXPECT_FALSE(unbridged.HasBridgePriors());
}

// Pose-graph edges of 2 cm, 0.005 rad and 1% scale between keyframes.
EssentialGraphOptions CorrectionGraph() {
  return {.edge_translation_sigma = 0.02, .edge_rotation_sigma = 0.005, .edge_scale_sigma = 0.01};
}

struct BridgedRoute {
  SyntheticRoute route;
  Map map;
  std::vector<KeyframeId> keyframes;
  Eigen::Vector3d predicted_centre;
};

// Keyframes along the route every 3 degrees; the closed map's camera stood still 0.3 m off
// the first keyframe's centre, so the bridge predicts it there (gap 0.5 s: sigma 7.5 cm).
void BridgeToFirstKeyframe(MapSession& session, BridgedRoute& scene) {
  std::vector<Rigid3> poses;
  for (int i = 0; i < 9; ++i) poses.push_back(scene.route.CamFromWorld(3.0 * i));
  scene.keyframes = scene.route.AddRoute(poses, &scene.map);
  Rigid3 standing = poses.front().Inverse();
  standing.translation += Eigen::Vector3d(0.0, 0.3, 0.0);
  scene.predicted_centre = standing.translation;
  CloseAfterMotion(session, standing, Eigen::Vector3d::Zero());
  session.AddBridgePrior(scene.keyframes.front(), 1.5, false);
}

double CentreDistance(const Map& map, KeyframeId keyframe, const Eigen::Vector3d& centre) {
  return map.Read([&](const MapData& data) {
    return (data.FindKeyframe(keyframe)->CameraCenter() - centre).norm();
  });
}

TEST(MapSessionBridge, CorrectionPullsTheFirstKeyframeTowardsThePredictionAndHoldsIt) {
  MapSession session({}, true);
  BridgedRoute scene;
  BridgeToFirstKeyframe(session, scene);
  ASSERT_TRUE(session.HasBridgePriors());
  // The markers hold the last keyframe where it is (1 cm, 0.01 rad).
  const KeyframeId last = scene.keyframes.back();
  const Eigen::Vector3d last_centre = scene.route.CamFromWorld(24.0).Inverse().translation;
  const std::vector<KeyframePosePrior> marker_priors = {
      {last, scene.route.CamFromWorld(24.0).Inverse(), 1e4 * Matrix6d::Identity()}};
  const double before = CentreDistance(scene.map, scene.keyframes.front(), scene.predicted_centre);
  const EssentialGraphResult result =
      session.CorrectAcrossBridge(scene.map, marker_priors, CorrectionGraph());
  ASSERT_TRUE(result.applied) << result.summary.message;
  EXPECT_EQ(result.num_priors, 2);
  EXPECT_NEAR(before, 0.3, 1e-9);
  EXPECT_LT(CentreDistance(scene.map, scene.keyframes.front(), scene.predicted_centre), 0.25);
  EXPECT_LT(CentreDistance(scene.map, last, last_centre), 0.02);
  // Used up; its adjustment version is held for the whole-map bundle adjustments.
  EXPECT_FALSE(session.HasBridgePriors());
  ASSERT_EQ(session.held_bridge_priors().size(), 1u);
  EXPECT_EQ(session.held_bridge_priors()[0].keyframe, scene.keyframes.front());
  EXPECT_NEAR(session.held_bridge_priors()[0].information(0, 0), InverseSquare(0.0625), 1e-6);
  EXPECT_EQ(session.stats().num_bridged_gaps, 1);
  EXPECT_FALSE(session.CorrectAcrossBridge(scene.map, marker_priors, CorrectionGraph()).applied);
  EXPECT_EQ(session.stats().num_bridged_gaps, 1);
  session.StartNewMap(std::nullopt);
  EXPECT_TRUE(session.held_bridge_priors().empty());
}

TEST(MapSessionBridge, PriorsAreNotHeldWhenAdjustmentsLeaveThemOut) {
  MapSessionOptions options;
  options.bridge_in_bundle_adjustment = false;
  MapSession session(options, true);
  BridgedRoute scene;
  BridgeToFirstKeyframe(session, scene);
  const EssentialGraphResult result = session.CorrectAcrossBridge(scene.map, {}, CorrectionGraph());
  ASSERT_TRUE(result.applied) << result.summary.message;
  EXPECT_TRUE(session.held_bridge_priors().empty());
  EXPECT_EQ(session.stats().num_bridged_gaps, 1);
}

}  // namespace
}  // namespace arucoslam
