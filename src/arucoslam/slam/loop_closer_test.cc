#include "arucoslam/slam/loop_closer.h"

#include <gtest/gtest.h>

#include "arucoslam/optim/global_bundle_adjustment.h"
#include "arucoslam/slam/synthetic_loop_map.h"

namespace arucoslam {
namespace {

// The drifted map of the wall loop (slam/synthetic_loop_map.h) in its own Map.
struct WallLoop {
  Map map;
  SyntheticLoopMap scene;
  std::vector<KeyframeId> keyframes;
  std::vector<double> local_scales;
};

void Build(WallLoop& wall, const SyntheticLoopOptions& loop = {}) {
  SyntheticLoopMapOptions options;
  options.loop = loop;
  wall.scene = BuildSyntheticLoopMap(options, &wall.map);
  wall.keyframes = wall.scene.keyframes;
  wall.local_scales = wall.scene.local_scales;
}

double KeyframeRms(const WallLoop& wall) { return KeyframeCentreRms(wall.map, wall.scene); }

TEST(LoopCloserTest, ClosesTheDriftedLoopAndFusesDuplicates) {
  WallLoop scene;
  Build(scene);
  ASSERT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
  const std::size_t points_before = scene.map.NumMapPoints();
  const double rms_before = KeyframeRms(scene);
  LoopCloser closer(scene.map);
  const LoopClosureResult result = closer.CloseLoop(scene.keyframes.back(), scene.keyframes[0]);
  ASSERT_TRUE(result.closed) << result.reason;
  const double rms_after = KeyframeRms(scene);
  std::printf(
      "matches %d, sim3 inliers %d, projected %d, fused %d, scale %.3f; keyframe RMS %.3f -> "
      "%.3f m\n",
      result.num_matches, result.num_sim3_inliers, result.num_projected_matches,
      result.num_fused_points, result.candidate_from_current.scale, rms_before, rms_after);
  // The last keyframe's local scale is 1.01^39 = 1.474: the loop maps it back by 1 / 1.474.
  EXPECT_NEAR(result.candidate_from_current.scale, 1.0 / scene.local_scales.back(), 0.02);
  EXPECT_GE(result.num_sim3_inliers, 50);
  EXPECT_GT(result.num_fused_points, 100);
  EXPECT_LT(scene.map.NumMapPoints(), points_before - 100);  // duplicates merged
  EXPECT_LT(rms_after, rms_before / 5.0);
  EXPECT_TRUE(closer.global_bundle_adjustment_requested());
  EXPECT_EQ(closer.closed_loops().size(), 1u);
  EXPECT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

// Descriptor matching that keeps only near-identical descriptors (at most 2 differing bits
// where up to 4 differ) finds part of the overlap; search by projection with the solved Sim3 must
// find the rest in the current keyframe.
TEST(LoopCloserTest, SearchByProjectionFindsTheMatchesDescriptorMatchingMissed) {
  WallLoop scene;
  Build(scene);
  LoopCloserOptions options;
  options.matching.max_distance = 2;
  LoopCloser closer(scene.map, options);
  const LoopClosureResult result = closer.CloseLoop(scene.keyframes.back(), scene.keyframes[0]);
  ASSERT_TRUE(result.closed) << result.reason;
  std::printf("strict matching: %d matches, %d inliers, %d projected, %d fused\n",
              result.num_matches, result.num_sim3_inliers, result.num_projected_matches,
              result.num_fused_points);
  EXPECT_LT(result.num_matches, 150);  // the full overlap is 178 points
  EXPECT_GT(result.num_projected_matches, 30);
  EXPECT_GE(result.num_sim3_inliers + result.num_projected_matches, 170);
  EXPECT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

// Markers make the map metric: the loop is rigid and the graph keeps every scale at 1.
TEST(LoopCloserTest, MetricMapClosesWithARigidTransform) {
  WallLoop scene;
  SyntheticLoopOptions options;
  options.scale_drift = 1.0;
  Build(scene, options);
  const double rms_before = KeyframeRms(scene);
  LoopCloserOptions closer_options;
  closer_options.metric_map = true;
  LoopCloser closer(scene.map, closer_options);
  const LoopClosureResult result = closer.CloseLoop(scene.keyframes.back(), scene.keyframes[0]);
  ASSERT_TRUE(result.closed) << result.reason;
  EXPECT_EQ(result.candidate_from_current.scale, 1.0);
  const double rms_after = KeyframeRms(scene);
  std::printf("metric map: keyframe RMS %.3f -> %.3f m\n", rms_before, rms_after);
  EXPECT_LT(rms_after, rms_before / 5.0);
}

// A world-anchored map: every fifth keyframe has an absolute pose prior (as its markers would
// give, here the truth with 1 cm / 0.01 rad) that the loop's graph keeps, with no keyframe
// held fixed; the loop alone (about keyframe 0) leaves the rest of the drift in place.
TEST(LoopCloserTest, PosePriorsKeepTheWorldAnchoredKeyframesInPlace) {
  SyntheticLoopOptions options;
  options.scale_drift = 1.0;
  LoopCloserOptions closer_options;
  closer_options.metric_map = true;
  WallLoop plain;
  Build(plain, options);
  ASSERT_TRUE(LoopCloser(plain.map, closer_options)
                  .CloseLoop(plain.keyframes.back(), plain.keyframes[0])
                  .closed);
  WallLoop anchored;
  Build(anchored, options);
  const double rms_before = KeyframeRms(anchored);
  std::vector<KeyframePosePrior> priors;
  for (std::size_t i = 0; i < anchored.keyframes.size(); i += 5) {
    KeyframePosePrior prior;
    prior.keyframe = anchored.keyframes[i];
    prior.world_from_cam = anchored.scene.loop.truth_cam_from_world[i].Inverse();
    prior.information.topLeftCorner<3, 3>() *= 1.0 / (0.01 * 0.01);
    prior.information.bottomRightCorner<3, 3>() *= 1.0 / (0.01 * 0.01);
    priors.push_back(prior);
  }
  EssentialGraphOptions graph;
  graph.edge_translation_sigma = 0.02;
  graph.edge_rotation_sigma = 0.005;
  graph.edge_scale_sigma = 0.01;
  LoopCloser closer(anchored.map, closer_options);
  int calls = 0;
  closer.SetPosePriors([&] { ++calls; return priors; }, graph);
  const LoopClosureResult result =
      closer.CloseLoop(anchored.keyframes.back(), anchored.keyframes[0]);
  ASSERT_TRUE(result.closed) << result.reason;
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(result.essential_graph.num_priors, static_cast<int>(priors.size()));
  const double rms_plain = KeyframeRms(plain);
  const double rms_anchored = KeyframeRms(anchored);
  std::printf("keyframe RMS %.3f m; loop alone %.3f m, with priors %.3f m\n", rms_before,
              rms_plain, rms_anchored);
  // Measured: 2.662 m before the loop, 0.151 m after it alone, 0.010 m with the priors.
  EXPECT_LT(rms_anchored, 0.03);
  EXPECT_GT(rms_plain, 0.1);
  EXPECT_EQ(anchored.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

// The requested global bundle adjustment then makes the whole map consistent with the
// (exact) keypoints: lower reprojection error and keyframe error.
TEST(LoopCloserTest, GlobalBundleAdjustmentAfterTheLoopLowersTheError) {
  WallLoop scene;
  Build(scene);
  LoopCloser closer(scene.map);
  ASSERT_TRUE(closer.CloseLoop(scene.keyframes.back(), scene.keyframes[0]).closed);
  ASSERT_TRUE(closer.global_bundle_adjustment_requested());
  const double rms_loop = KeyframeRms(scene);
  const GlobalBundleAdjustmentResult result = RunGlobalBundleAdjustment(scene.map);
  ASSERT_TRUE(result.applied) << result.summary.message;
  const double rms_global = KeyframeRms(scene);
  std::printf("global BA: %s; keyframe RMS %.3f -> %.3f m\n", result.summary.BriefReport().c_str(),
              rms_loop, rms_global);
  EXPECT_LT(result.summary.final_rms_px, 0.5 * result.summary.initial_rms_px);
  EXPECT_LT(rms_global, rms_loop);
  EXPECT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

TEST(LoopCloserTest, RejectsALoopThatTurnsTheMapMoreThanDriftCan) {
  // The synthetic loop drifts 0.01 rad per keyframe: 39 steps ask for a 22.3 degree turn,
  // accepted under a 30 degree bound and refused by a 15 degree one (as a look-alike place
  // seen from elsewhere would be).
  for (const double max_deg : {30.0, 15.0}) {
    WallLoop scene;
    Build(scene);
    const std::uint64_t version = scene.map.Version();
    LoopCloserOptions options;
    options.max_correction_rotation_deg = max_deg;
    LoopCloser closer(scene.map, options);
    const LoopClosureResult result = closer.CloseLoop(scene.keyframes.back(), scene.keyframes[0]);
    EXPECT_NEAR(result.correction_rotation_deg, 39 * 0.01 * 180.0 / M_PI, 1.0);
    EXPECT_EQ(result.closed, max_deg == 30.0) << result.reason;
    if (!result.closed) EXPECT_EQ(scene.map.Version(), version);  // nothing written
  }
}

TEST(LoopCloserTest, RejectsKeyframesThatDoNotOverlap) {
  WallLoop scene;
  Build(scene);
  const std::uint64_t version = scene.map.Version();
  LoopCloser closer(scene.map);
  // Keyframe 20 looks at the opposite side of the wall.
  const LoopClosureResult result = closer.CloseLoop(scene.keyframes.back(), scene.keyframes[20]);
  EXPECT_FALSE(result.closed);
  EXPECT_FALSE(result.reason.empty());
  EXPECT_EQ(scene.map.Version(), version);  // nothing written
  EXPECT_FALSE(closer.global_bundle_adjustment_requested());
}

}  // namespace
}  // namespace arucoslam
