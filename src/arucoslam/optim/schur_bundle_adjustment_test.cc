#include "arucoslam/optim/bundle_adjustment.h"

#include <gtest/gtest.h>

#include "arucoslam/optim/synthetic_scene.h"

namespace arucoslam {
namespace {

// A noisy synthetic window with every pose but the first two (the gauge and the scale) and
// every point perturbed.
BundleAdjustmentProblem PerturbedWindow(int num_poses, int num_points, std::uint32_t seed) {
  SyntheticSceneOptions scene;
  scene.num_poses = num_poses;
  scene.num_points = num_points;
  scene.noise_px = 0.5;
  scene.seed = seed;
  return PerturbedScene(MakeSyntheticScene(scene), seed + 100);
}

double MaxCentreDistance(const BundleAdjustmentProblem& a, const BundleAdjustmentProblem& b) {
  double distance = 0.0;
  for (std::size_t i = 0; i < a.poses.size(); ++i) {
    distance = std::max(distance, (a.poses[i].cam_from_world.Inverse().translation -
                                   b.poses[i].cam_from_world.Inverse().translation)
                                      .norm());
  }
  return distance;
}

double MaxPointDistance(const BundleAdjustmentProblem& a, const BundleAdjustmentProblem& b) {
  double distance = 0.0;
  for (std::size_t j = 0; j < a.points.size(); ++j) {
    distance = std::max(distance, (a.points[j].p_in_world - b.points[j].p_in_world).norm());
  }
  return distance;
}

TEST(SchurBundleAdjustmentTest, ReachesTheOptimumCeresReaches) {
  for (std::uint32_t seed : {1u, 2u, 3u}) {
    const BundleAdjustmentProblem start = PerturbedWindow(10, 600, seed);
    BundleAdjustmentOptions options;
    options.max_iterations = 50;
    options.function_tolerance = 1e-12;
    BundleAdjustmentProblem by_ceres = start;
    const BundleAdjustmentSummary ceres = SolveBundleAdjustmentWithCeres(options, &by_ceres);
    BundleAdjustmentProblem by_schur = start;
    const BundleAdjustmentSummary schur = SolveBundleAdjustment(options, &by_schur);
    ASSERT_TRUE(ceres.success);
    ASSERT_TRUE(schur.success) << schur.message;
    EXPECT_NEAR(schur.initial_cost, ceres.initial_cost, 1e-9 * ceres.initial_cost);
    EXPECT_NEAR(schur.final_cost, ceres.final_cost, 1e-6 * ceres.final_cost) << "seed " << seed;
    EXPECT_LT(MaxCentreDistance(by_schur, by_ceres), 1e-5) << "seed " << seed;
    EXPECT_LT(MaxPointDistance(by_schur, by_ceres), 1e-4) << "seed " << seed;
    EXPECT_EQ(schur.num_outliers, ceres.num_outliers);
    EXPECT_NEAR(schur.final_rms_px, 0.5 * std::sqrt(2.0), 0.1);  // the pixel noise
  }
}

TEST(SchurBundleAdjustmentTest, LeavesFixedPosesAndPointsExactlyWhereTheyAre) {
  BundleAdjustmentProblem problem = PerturbedWindow(8, 400, 4);
  problem.points[5].fixed = true;
  problem.points[5].p_in_world += Eigen::Vector3d(0.05, 0.0, 0.0);
  const BundleAdjustmentProblem start = problem;
  const BundleAdjustmentSummary summary = SolveBundleAdjustment({}, &problem);
  ASSERT_TRUE(summary.success);
  for (int i : {0, 1}) {
    EXPECT_EQ(problem.poses[i].cam_from_world.translation, start.poses[i].cam_from_world.translation);
    EXPECT_EQ(problem.poses[i].cam_from_world.rotation.coeffs(),
              start.poses[i].cam_from_world.rotation.coeffs());
  }
  EXPECT_EQ(problem.points[5].p_in_world, start.points[5].p_in_world);
  EXPECT_GT(MaxCentreDistance(problem, start), 1e-3);  // the free poses moved
}

TEST(SchurBundleAdjustmentTest, GrossErrorsAreDownWeightedAndFlaggedAsCeresFlagsThem) {
  BundleAdjustmentProblem start = PerturbedWindow(10, 600, 5);
  for (std::size_t k = 0; k < start.observations.size(); k += 50) {
    start.observations[k].pixel += Eigen::Vector2d(25.0, -18.0);
  }
  BundleAdjustmentOptions options;
  options.max_iterations = 50;
  options.function_tolerance = 1e-12;
  BundleAdjustmentProblem by_ceres = start;
  BundleAdjustmentProblem by_schur = start;
  const BundleAdjustmentSummary ceres = SolveBundleAdjustmentWithCeres(options, &by_ceres);
  const BundleAdjustmentSummary schur = SolveBundleAdjustment(options, &by_schur);
  ASSERT_TRUE(schur.success);
  EXPECT_NEAR(schur.final_cost, ceres.final_cost, 1e-6 * ceres.final_cost);
  EXPECT_EQ(schur.outliers, ceres.outliers);
  EXPECT_GE(schur.num_outliers, static_cast<int>(start.observations.size() / 50));
}

TEST(SchurBundleAdjustmentTest, AStopRequestEndsTheSolveWithAUsableIterate) {
  BundleAdjustmentProblem problem = PerturbedWindow(10, 600, 6);
  BundleAdjustmentOptions options;
  options.max_iterations = 50;
  options.function_tolerance = 1e-12;
  options.min_iterations_before_stop = 2;
  options.stop_requested = [] { return true; };
  const BundleAdjustmentSummary summary = SolveBundleAdjustment(options, &problem);
  EXPECT_TRUE(summary.success);
  EXPECT_TRUE(summary.stopped_early);
  EXPECT_EQ(summary.num_iterations, 2);
  EXPECT_LT(summary.final_cost, summary.initial_cost);
}

TEST(SchurBundleAdjustmentTest, APointBehindACameraContributesNothingAndIsAnOutlier) {
  BundleAdjustmentProblem problem = PerturbedWindow(6, 300, 7);
  const std::size_t bad = problem.observations[0].point_index;
  problem.points[bad].p_in_world = problem.poses[problem.observations[0].pose_index]
                                       .cam_from_world.Inverse() *
                                   Eigen::Vector3d(0.0, 0.0, -2.0);
  problem.points[bad].fixed = true;
  const BundleAdjustmentSummary summary = SolveBundleAdjustment({}, &problem);
  ASSERT_TRUE(summary.success);
  EXPECT_TRUE(summary.outliers[0]);
  EXPECT_LT(summary.final_rms_px, 1.0);
}

TEST(SchurBundleAdjustmentTest, RefusesABadProblemNamingIt) {
  BundleAdjustmentProblem problem = PerturbedWindow(4, 100, 8);
  problem.observations[3].point_index = problem.points.size();
  const BundleAdjustmentSummary summary = SolveBundleAdjustment({}, &problem);
  EXPECT_FALSE(summary.success);
  EXPECT_NE(summary.message.find("observation 3"), std::string::npos) << summary.message;
}

}  // namespace
}  // namespace arucoslam
