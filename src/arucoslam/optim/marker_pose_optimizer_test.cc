#include "arucoslam/optim/marker_pose_optimizer.h"

#include <gtest/gtest.h>

#include "arucoslam/optim/marker_bundle_adjustment_synthetic.h"

namespace arucoslam {
namespace {

// The observations of one pose of the synthetic scene.
struct FrameData {
  Rigid3 true_cam_from_world;
  std::vector<PoseObservation> keypoints;
  std::vector<MarkerPoseObservation> markers;
  PinholeIntrinsics intrinsics;
};

FrameData Frame(const MarkerBundleAdjustmentProblem& scene, std::size_t pose) {
  FrameData frame;
  frame.true_cam_from_world = scene.keypoints.poses[pose].cam_from_world;
  frame.intrinsics = scene.keypoints.intrinsics;
  for (const auto& observation : scene.keypoints.observations) {
    if (observation.pose_index != pose) continue;
    frame.keypoints.push_back(
        {scene.keypoints.points[observation.point_index].p_in_world, observation.pixel, 1.0});
  }
  for (const auto& observation : scene.marker_observations) {
    if (observation.pose_index != pose) continue;
    const auto& marker = scene.markers[observation.marker_index];
    frame.markers.push_back({marker.world_from_marker, marker.size, observation.corners_px, 1.0});
  }
  return frame;
}

Rigid3 Perturbed(const Rigid3& pose, double translation, double rotation) {
  Vector6d delta;
  delta << translation, -translation, 0.5 * translation, rotation, -rotation, 0.5 * rotation;
  return Rigid3::Exp(delta) * pose;
}

double CentreError(const Rigid3& a, const Rigid3& b) {
  return (a.Inverse().translation - b.Inverse().translation).norm();
}

SyntheticMarkerSceneOptions Noisy() {
  SyntheticMarkerSceneOptions options;
  options.noise_px = 0.5;
  options.corner_noise_px = 0.3;
  return options;
}

TEST(MarkerPoseOptimizerTest, MarkersAloneGiveTheExactPose) {
  const auto scene = MakeSyntheticMarkerScene(SyntheticMarkerSceneOptions());
  FrameData frame = Frame(scene, 4);
  ASSERT_FALSE(frame.markers.empty());
  const Rigid3 start = Perturbed(frame.true_cam_from_world, 0.2, 0.05);
  const auto result = OptimizePoseWithMarkers({}, frame.markers, start, frame.intrinsics);
  ASSERT_TRUE(result.success);  // no keypoint, but an inlier marker
  EXPECT_EQ(result.num_marker_inliers, static_cast<int>(frame.markers.size()));
  EXPECT_LT(CentreError(result.cam_from_world, frame.true_cam_from_world), 1e-6);
  EXPECT_LT(result.final_marker_rms_px, 1e-6);
}

TEST(MarkerPoseOptimizerTest, KeypointsAndMarkersTogetherConverge) {
  const auto scene = MakeSyntheticMarkerScene(Noisy());
  for (std::size_t pose : {2u, 8u, 14u}) {
    const FrameData frame = Frame(scene, pose);
    ASSERT_FALSE(frame.markers.empty()) << pose;
    const Rigid3 start = Perturbed(frame.true_cam_from_world, 0.1, 0.03);
    const auto result =
        OptimizePoseWithMarkers(frame.keypoints, frame.markers, start, frame.intrinsics);
    ASSERT_TRUE(result.success);
    EXPECT_LT(CentreError(result.cam_from_world, frame.true_cam_from_world), 0.01) << pose;
    EXPECT_LT(RotationAngle(result.cam_from_world.rotation *
                            frame.true_cam_from_world.rotation.inverse()),
              0.002);
    EXPECT_LT(result.final_rms_px, 0.8);
    EXPECT_GT(result.num_inliers, static_cast<int>(0.9 * frame.keypoints.size()));
  }
}

TEST(MarkerPoseOptimizerTest, AMisplacedMarkerIsRejectedAndDoesNotPull) {
  const auto scene = MakeSyntheticMarkerScene(Noisy());
  FrameData frame = Frame(scene, 4);
  ASSERT_FALSE(frame.markers.empty());
  // The map says the marker is 40 cm away from where it really is.
  frame.markers[0].world_from_marker.translation += Eigen::Vector3d(0.0, 0.4, 0.0);
  const auto result = OptimizePoseWithMarkers(frame.keypoints, frame.markers,
                                              frame.true_cam_from_world, frame.intrinsics);
  ASSERT_TRUE(result.success);
  EXPECT_FALSE(result.marker_inliers[0]);
  EXPECT_LT(CentreError(result.cam_from_world, frame.true_cam_from_world), 0.01);
}

TEST(MarkerPoseOptimizerTest, FewKeypointsFailWithoutAMarker) {
  const auto scene = MakeSyntheticMarkerScene(Noisy());
  FrameData frame = Frame(scene, 4);
  frame.keypoints.resize(5);  // below min_inliers (10)
  EXPECT_FALSE(
      OptimizePoseWithMarkers(frame.keypoints, {}, frame.true_cam_from_world, frame.intrinsics)
          .success);
  EXPECT_TRUE(OptimizePoseWithMarkers(frame.keypoints, frame.markers, frame.true_cam_from_world,
                                      frame.intrinsics)
                  .success);
}

}  // namespace
}  // namespace arucoslam
