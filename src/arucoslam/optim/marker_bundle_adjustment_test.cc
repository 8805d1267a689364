#include "arucoslam/optim/marker_bundle_adjustment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>

#include "arucoslam/geometry/sim3.h"
#include "arucoslam/optim/marker_bundle_adjustment_synthetic.h"

namespace arucoslam {
namespace {

SyntheticMarkerSceneOptions NoisyScene() {
  SyntheticMarkerSceneOptions options;
  options.noise_px = 0.5;
  options.corner_noise_px = 0.3;
  return options;
}

Eigen::Vector3d Centre(const Rigid3& cam_from_world) {
  return cam_from_world.Inverse().translation;
}

// Moves the whole estimate by a similarity (the map frame of a monocular run) and adds a
// random drift to every pose: what a drifted, wrongly scaled keypoint map looks like.
void Distort(const Sim3& moved_from_true, double drift, MarkerBundleAdjustmentProblem* problem) {
  std::mt19937 random(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (auto& pose : problem->keypoints.poses) {
    const Rigid3 world_from_cam = moved_from_true.TransformPose(pose.cam_from_world.Inverse());
    Vector6d delta;
    for (int k = 0; k < 6; ++k) delta[k] = drift * normal(random);
    pose.cam_from_world = Rigid3::Exp(delta) * world_from_cam.Inverse();
  }
  for (auto& point : problem->keypoints.points)
    point.p_in_world = moved_from_true * point.p_in_world;
}

// A monocular map's frame: 8% too large, turned 0.05 rad about z and shifted.
Sim3 ScaledMapFrame() {
  return Sim3(1.08, Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitZ())),
              Eigen::Vector3d(0.2, -0.1, 0.05));
}

double MaxCentreError(const MarkerBundleAdjustmentProblem& a,
                      const MarkerBundleAdjustmentProblem& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.keypoints.poses.size(); ++i) {
    worst = std::max(worst, (Centre(a.keypoints.poses[i].cam_from_world) -
                             Centre(b.keypoints.poses[i].cam_from_world))
                                .norm());
  }
  return worst;
}

TEST(MarkerBundleAdjustmentTest, SceneSeesEveryMarkerFromSeveralPoses) {
  const MarkerBundleAdjustmentProblem scene = MakeSyntheticMarkerScene(NoisyScene());
  std::vector<int> views(scene.markers.size(), 0);
  for (const auto& observation : scene.marker_observations) ++views[observation.marker_index];
  for (std::size_t m = 0; m < views.size(); ++m) EXPECT_GE(views[m], 3) << "marker " << m;
  EXPECT_GT(scene.keypoints.observations.size(), 20 * 50u);
}

TEST(MarkerBundleAdjustmentTest, FixedMarkersPullAScaledDriftedMapIntoTheWorld) {
  const MarkerBundleAdjustmentProblem truth = MakeSyntheticMarkerScene(NoisyScene());
  MarkerBundleAdjustmentProblem problem = truth;
  Distort(ScaledMapFrame(), 0.005, &problem);
  ASSERT_GT(MaxCentreError(problem, truth), 0.3);
  MarkerBundleAdjustmentOptions options;
  options.solver.max_iterations = 50;
  const MarkerBundleAdjustmentSummary summary = SolveMarkerBundleAdjustment(options, &problem);
  ASSERT_TRUE(summary.success) << summary.message;
  EXPECT_LT(summary.final_marker_rms_px, 0.6) << summary.BriefReport();
  EXPECT_LT(summary.final_keypoint_rms_px, 0.8) << summary.BriefReport();
  EXPECT_LT(MaxCentreError(problem, truth), 0.02);
  // Metric scale: the length of the path within 0.5%.
  const double length = (Centre(problem.keypoints.poses.back().cam_from_world) -
                         Centre(problem.keypoints.poses.front().cam_from_world))
                            .norm();
  const double true_length = (Centre(truth.keypoints.poses.back().cam_from_world) -
                              Centre(truth.keypoints.poses.front().cam_from_world))
                                 .norm();
  EXPECT_NEAR(length / true_length, 1.0, 0.005);
  // The markers did not move.
  for (std::size_t m = 0; m < truth.markers.size(); ++m) {
    EXPECT_EQ(problem.markers[m].world_from_marker.translation,
              truth.markers[m].world_from_marker.translation);
  }
}

TEST(MarkerBundleAdjustmentTest, WithoutMarkersTheScaleErrorStays) {
  // Control for the test above: the same start, keypoints only, the first pose held.
  const MarkerBundleAdjustmentProblem truth = MakeSyntheticMarkerScene(NoisyScene());
  MarkerBundleAdjustmentProblem problem = truth;
  Distort(Sim3(1.08, Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero()), 0.005, &problem);
  problem.marker_observations.clear();
  problem.keypoints.poses[0].fixed = true;
  MarkerBundleAdjustmentOptions options;
  options.solver.max_iterations = 50;
  ASSERT_TRUE(SolveMarkerBundleAdjustment(options, &problem).success);
  EXPECT_GT(MaxCentreError(problem, truth), 0.2);
}

TEST(MarkerBundleAdjustmentTest, PositionPriorOnTheLastCameraTakesTheScaleErrorOut) {
  // The start of the test above, plus where the last camera is (the bridge over a tracking
  // gap gives that for a map's first keyframe). The held first pose is at its true place, so
  // what the keypoints leave free is the scale about it, which the prior fixes.
  const MarkerBundleAdjustmentProblem truth = MakeSyntheticMarkerScene(NoisyScene());
  MarkerBundleAdjustmentProblem start = truth;
  Distort(Sim3(1.08, Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero()), 0.005, &start);
  start.marker_observations.clear();
  start.keypoints.poses[0] = {truth.keypoints.poses[0].cam_from_world, true};
  MarkerBundleAdjustmentOptions options;
  options.solver.max_iterations = 50;

  MarkerBundleAdjustmentProblem without = start;
  ASSERT_TRUE(SolveMarkerBundleAdjustment(options, &without).success);
  EXPECT_GT(MaxCentreError(without, truth), 0.2);

  MarkerBundleAdjustmentProblem with = start;
  const std::size_t last = with.keypoints.poses.size() - 1;
  with.position_priors.push_back({last, Centre(truth.keypoints.poses[last].cam_from_world), 0.02});
  const MarkerBundleAdjustmentSummary summary = SolveMarkerBundleAdjustment(options, &with);
  ASSERT_TRUE(summary.success) << summary.message;
  EXPECT_EQ(summary.num_position_priors, 1);
  EXPECT_LT(summary.max_position_prior_sigmas, 1.0);
  EXPECT_LT(MaxCentreError(with, truth), 0.03) << MaxCentreError(without, truth);
}

TEST(MarkerBundleAdjustmentTest, StopRequestEndsTheJointSolveEarly) {
  // The start of FixedMarkersPullAScaledDriftedMapIntoTheWorld; local mapping stops its BA
  // this way for a waiting keyframe.
  const MarkerBundleAdjustmentProblem truth = MakeSyntheticMarkerScene(NoisyScene());
  MarkerBundleAdjustmentProblem start = truth;
  Distort(ScaledMapFrame(), 0.005, &start);
  MarkerBundleAdjustmentOptions options;
  options.solver.max_iterations = 50;
  MarkerBundleAdjustmentProblem full = start;
  const MarkerBundleAdjustmentSummary full_summary = SolveMarkerBundleAdjustment(options, &full);
  ASSERT_TRUE(full_summary.success) << full_summary.message;
  EXPECT_FALSE(full_summary.stopped_early);
  ASSERT_GT(full_summary.num_iterations, 1);

  options.solver.stop_requested = [] { return true; };
  MarkerBundleAdjustmentProblem stopped = start;
  const MarkerBundleAdjustmentSummary summary = SolveMarkerBundleAdjustment(options, &stopped);
  ASSERT_TRUE(summary.success) << summary.message;
  EXPECT_TRUE(summary.stopped_early);
  EXPECT_EQ(summary.num_iterations, 1);
  // One step was taken and kept: the map moved towards the markers, not all the way.
  EXPECT_LT(summary.final_cost, summary.initial_cost);
  EXPECT_GT(summary.final_cost, full_summary.final_cost);
  EXPECT_LT(MaxCentreError(stopped, truth), MaxCentreError(start, truth));
}

TEST(MarkerBundleAdjustmentTest, PositionPriorsAreChecked) {
  MarkerBundleAdjustmentProblem problem = MakeSyntheticMarkerScene(NoisyScene());
  problem.position_priors.push_back({problem.keypoints.poses.size(), Eigen::Vector3d::Zero(), 0.1});
  MarkerBundleAdjustmentSummary summary = SolveMarkerBundleAdjustment({}, &problem);
  EXPECT_FALSE(summary.success);
  EXPECT_NE(summary.message.find("position prior 0: index out of range"), std::string::npos)
      << summary.message;
  problem.position_priors.front() = {0, Eigen::Vector3d::Zero(), 0.0};
  summary = SolveMarkerBundleAdjustment({}, &problem);
  EXPECT_FALSE(summary.success);
  EXPECT_NE(summary.message.find("position prior 0: sigma <= 0"), std::string::npos)
      << summary.message;
}

// Root mean square over the poses of the camera height error (metres) and of the angle
// between the camera's true and estimated up direction (radians).
std::pair<double, double> HeightAndTiltRms(const MarkerBundleAdjustmentProblem& estimate,
                                           const MarkerBundleAdjustmentProblem& truth) {
  double height = 0.0, tilt = 0.0;
  const std::size_t n = truth.keypoints.poses.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Rigid3& a = estimate.keypoints.poses[i].cam_from_world;
    const Rigid3& b = truth.keypoints.poses[i].cam_from_world;
    height += std::pow(Centre(a).z() - Centre(b).z(), 2);
    const Eigen::Vector3d up_a = a.rotation * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d up_b = b.rotation * Eigen::Vector3d::UnitZ();
    tilt += std::pow(std::acos(std::clamp(up_a.dot(up_b), -1.0, 1.0)), 2);
  }
  return {std::sqrt(height / n), std::sqrt(tilt / n)};
}

TEST(MarkerBundleAdjustmentTest, GroundPlanePriorHoldsAGroundVehicleOnItsPlane) {
  // A camera at a constant height, one marker near the start, few noisy keypoints: the far
  // poses' height and tilt rest on the keypoint chain alone unless the prior holds them.
  SyntheticMarkerSceneOptions scene = NoisyScene();
  scene.height_wobble_m = 0.0;
  scene.num_markers = 1;
  scene.noise_px = 2.0;
  scene.path_length_m = 12.0;
  scene.num_poses = 30;
  scene.num_points = 120;
  const MarkerBundleAdjustmentProblem truth = MakeSyntheticMarkerScene(scene);
  MarkerBundleAdjustmentProblem start = truth;
  Distort(Sim3(1.0, Eigen::Quaterniond(Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitY())),
               Eigen::Vector3d::Zero()),
          0.01, &start);
  MarkerBundleAdjustmentOptions options;
  options.solver.max_iterations = 100;

  MarkerBundleAdjustmentProblem free = start;
  const MarkerBundleAdjustmentSummary free_summary = SolveMarkerBundleAdjustment(options, &free);
  ASSERT_TRUE(free_summary.success) << free_summary.message;
  MarkerBundleAdjustmentProblem held = start;
  held.ground_plane_prior = GroundPlanePriorOptions{0.01, 0.005};
  const MarkerBundleAdjustmentSummary summary = SolveMarkerBundleAdjustment(options, &held);
  ASSERT_TRUE(summary.success) << summary.message;
  ASSERT_TRUE(summary.ground_plane.has_value());

  // The plane: height 1 m, up along the camera's -y (level mounting).
  EXPECT_NEAR(summary.ground_plane->height_m, 1.0, 0.005);
  EXPECT_LT((summary.ground_plane->up_in_camera - Eigen::Vector3d(0, -1, 0)).norm(), 0.005);
  const auto [free_height, free_tilt] = HeightAndTiltRms(free, truth);
  const auto [held_height, held_tilt] = HeightAndTiltRms(held, truth);
  std::printf("height RMS free %.4f held %.4f m; tilt RMS free %.5f held %.5f rad\n", free_height,
              held_height, free_tilt, held_tilt);
  EXPECT_LT(held_height, 0.005);
  EXPECT_LT(held_tilt, 0.003);
  EXPECT_LT(held_height, 0.5 * free_height);
  EXPECT_LT(held_tilt, 0.5 * free_tilt);
  // Holding the plane costs the keypoints almost nothing (2 px noise: about 2.8 px RMS).
  EXPECT_LT(summary.final_keypoint_rms_px, 1.05 * free_summary.final_keypoint_rms_px);
}

TEST(MarkerBundleAdjustmentTest, UnknownMarkersAreEstimatedAgainstOneKnownMarker) {
  const MarkerBundleAdjustmentProblem truth = MakeSyntheticMarkerScene(NoisyScene());
  MarkerBundleAdjustmentProblem problem = truth;
  for (std::size_t m = 1; m < problem.markers.size(); ++m) problem.markers[m].fixed = false;
  // The optimum reached from the truth: what the noise allows.
  MarkerBundleAdjustmentProblem from_truth = problem;
  MarkerBundleAdjustmentOptions options;
  options.solver.max_iterations = 100;
  options.solver.function_tolerance = 1e-10;
  ASSERT_TRUE(SolveMarkerBundleAdjustment(options, &from_truth).success);

  Distort(Sim3(1.03, Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.05, 0.0, 0.0)), 0.003,
          &problem);
  std::mt19937 random(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (std::size_t m = 1; m < problem.markers.size(); ++m) {
    Vector6d delta;
    for (int k = 0; k < 3; ++k) delta[k] = 0.1 * normal(random);
    for (int k = 3; k < 6; ++k) delta[k] = 0.08 * normal(random);
    problem.markers[m].world_from_marker =
        Rigid3::Exp(delta) * problem.markers[m].world_from_marker;
  }
  const auto summary = SolveMarkerBundleAdjustment(options, &problem);
  ASSERT_TRUE(summary.success) << summary.message;
  EXPECT_EQ(summary.num_marker_outliers, 0) << summary.BriefReport();
  for (std::size_t m = 1; m < problem.markers.size(); ++m) {
    const Rigid3& estimate = problem.markers[m].world_from_marker;
    const Rigid3& optimum = from_truth.markers[m].world_from_marker;
    const Rigid3& true_pose = truth.markers[m].world_from_marker;
    // Converged: the same optimum as from the truth.
    EXPECT_LT((estimate.translation - optimum.translation).norm(), 1e-3) << "marker " << m;
    EXPECT_LT(RotationAngle(estimate.rotation * optimum.rotation.inverse()), 1e-3);
    // Accurate: within the 3 cm the unknown-marker mapping must reach (0.5 px noise, the
    // farthest marker 10 m from the known one).
    EXPECT_LT((estimate.translation - true_pose.translation).norm(), 0.03) << "marker " << m;
    EXPECT_LT(RotationAngle(estimate.rotation * true_pose.rotation.inverse()), 0.05);
  }
}

TEST(MarkerBundleAdjustmentTest, AWrongMarkerObservationIsFlagged) {
  const MarkerBundleAdjustmentProblem truth = MakeSyntheticMarkerScene(NoisyScene());
  MarkerBundleAdjustmentProblem problem = truth;
  ASSERT_GT(problem.marker_observations.size(), 5u);
  for (auto& corner : problem.marker_observations[5].corners_px) corner += Eigen::Vector2d(30, 12);
  const auto summary = SolveMarkerBundleAdjustment({}, &problem);
  ASSERT_TRUE(summary.success);
  EXPECT_EQ(summary.num_marker_outliers, 1);
  EXPECT_TRUE(summary.marker_outliers[5]);
  EXPECT_LT(MaxCentreError(problem, truth), 0.02);  // the Huber loss kept it from pulling
}

// At the truth, the residuals are the noise: keypoints 0.5 px (sigma 1 px), corners 0.1 px,
// so the corner sigma that weighs both alike is 0.2 px; clamped when asked.
TEST(MarkerBundleAdjustmentTest, BalancedCornerSigmaFollowsTheNoiseRatio) {
  SyntheticMarkerSceneOptions options;
  options.noise_px = 0.5;
  options.corner_noise_px = 0.1;
  const MarkerBundleAdjustmentProblem scene = MakeSyntheticMarkerScene(options);
  const std::optional<double> sigma = BalancedCornerSigmaPx(scene, 0.01, 10.0);
  ASSERT_TRUE(sigma.has_value());
  EXPECT_NEAR(*sigma, 0.2, 0.03);
  EXPECT_DOUBLE_EQ(*BalancedCornerSigmaPx(scene, 0.5, 10.0), 0.5);
  options.corner_noise_px = 1.5;
  EXPECT_NEAR(*BalancedCornerSigmaPx(MakeSyntheticMarkerScene(options), 0.01, 10.0), 3.0, 0.45);
  MarkerBundleAdjustmentProblem no_markers = scene;
  no_markers.marker_observations.clear();
  EXPECT_FALSE(BalancedCornerSigmaPx(no_markers, 0.01, 10.0).has_value());
}

TEST(MarkerBundleAdjustmentTest, InvalidProblemsAreRejectedWithAReason) {
  MarkerBundleAdjustmentProblem problem = MakeSyntheticMarkerScene(NoisyScene());
  problem.marker_observations[0].marker_index = problem.markers.size();
  MarkerBundleAdjustmentSummary summary = SolveMarkerBundleAdjustment({}, &problem);
  EXPECT_FALSE(summary.success);
  EXPECT_NE(summary.message.find("index out of range"), std::string::npos) << summary.message;
  problem.marker_observations[0].marker_index = 0;
  problem.markers[1].size = 0.0;
  summary = SolveMarkerBundleAdjustment({}, &problem);
  EXPECT_FALSE(summary.success);
  EXPECT_NE(summary.message.find("size"), std::string::npos) << summary.message;
}

}  // namespace
}  // namespace arucoslam
