#include "arucoslam/optim/bundle_adjustment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "arucoslam/optim/synthetic_scene.h"

namespace arucoslam {
namespace {

struct Errors {
  double max_position_m = 0.0;
  double max_angle_rad = 0.0;
  double median_point_m = 0.0;
};

Errors Compare(const BundleAdjustmentProblem& estimate, const BundleAdjustmentProblem& truth) {
  Errors errors;
  for (std::size_t i = 0; i < truth.poses.size(); ++i) {
    const Rigid3& a = estimate.poses[i].cam_from_world;
    const Rigid3& b = truth.poses[i].cam_from_world;
    errors.max_position_m =
        std::max(errors.max_position_m, (a.Inverse().translation - b.Inverse().translation).norm());
    errors.max_angle_rad =
        std::max(errors.max_angle_rad, RotationAngle(a.rotation.conjugate() * b.rotation));
  }
  std::vector<double> point_errors;
  for (std::size_t j = 0; j < truth.points.size(); ++j) {
    point_errors.push_back((estimate.points[j].p_in_world - truth.points[j].p_in_world).norm());
  }
  std::nth_element(point_errors.begin(), point_errors.begin() + point_errors.size() / 2,
                   point_errors.end());
  errors.median_point_m = point_errors[point_errors.size() / 2];
  return errors;
}

// Perturbs every pose but the first two (which fix the gauge and the scale) and every point.
BundleAdjustmentProblem Perturb(const BundleAdjustmentProblem& truth, std::uint32_t seed,
                                double pose_sigma, double point_sigma) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  BundleAdjustmentProblem problem = truth;
  for (std::size_t i = 0; i < problem.poses.size(); ++i) {
    if (i < 2) {
      problem.poses[i].fixed = true;
      continue;
    }
    Vector6d delta;
    for (int k = 0; k < 6; ++k) delta[k] = pose_sigma * normal(random);
    problem.poses[i].cam_from_world = Rigid3::Exp(delta) * problem.poses[i].cam_from_world;
  }
  for (auto& point : problem.points) {
    point.p_in_world +=
        point_sigma * Eigen::Vector3d(normal(random), normal(random), normal(random));
  }
  return problem;
}

TEST(BundleAdjustmentTest, OptionsAndProblemChecks) {
  EXPECT_TRUE(BundleAdjustmentOptions{}.Check());
  BundleAdjustmentOptions options;
  options.huber_delta_px = -1.0;
  EXPECT_FALSE(options.Check());
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "huber_delta_px must be > 0, is -1");

  BundleAdjustmentProblem problem = MakeSyntheticScene({});
  std::string reason;
  EXPECT_TRUE(problem.Check(&reason)) << reason;
  problem.observations[5].point_index = problem.points.size();
  EXPECT_FALSE(problem.Check(&reason));
  EXPECT_NE(reason.find("observation 5: point index"), std::string::npos) << reason;
  const BundleAdjustmentSummary summary = SolveBundleAdjustment({}, &problem);
  EXPECT_FALSE(summary.success);
}

// One camera at the origin, points 2 m ahead projecting onto the principal point (300, 200).
TEST(BundleAdjustmentTest, FlagsObservationsBehindOrBeyondTheChiSquareGate) {
  BundleAdjustmentProblem problem;
  problem.intrinsics = {400.0, 400.0, 300.0, 200.0};
  problem.poses.push_back({Rigid3(), false});
  problem.points.push_back({Eigen::Vector3d(0.0, 0.0, 2.0), false});
  problem.points.push_back({Eigen::Vector3d(0.0, 0.0, -2.0), false});
  auto observe = [&](std::size_t point, double x_px, double sigma_px) {
    problem.observations.push_back({0, point, Eigen::Vector2d(x_px, 200.0), sigma_px});
  };
  observe(0, 300.0, 1.0);  // exact
  observe(0, 303.0, 1.0);  // 3 px at 1 px noise: chi-square 9
  observe(0, 303.0, 2.0);  // 3 px at 2 px noise: chi-square 2.25
  observe(1, 300.0, 1.0);  // behind the camera
  int num_outliers = -1;
  const std::vector<bool> outliers =
      FlagReprojectionOutliers(problem, kChiSquare2Dof95, &num_outliers);
  EXPECT_EQ(outliers, (std::vector<bool>{false, true, false, true}));
  EXPECT_EQ(num_outliers, 2);
}

TEST(BundleAdjustmentTest, PerturbedSceneConvergesToTruth) {
  SyntheticSceneOptions scene_options;
  scene_options.noise_px = 0.5;
  const BundleAdjustmentProblem truth = MakeSyntheticScene(scene_options);
  ASSERT_GT(truth.observations.size(), 5000u);
  BundleAdjustmentProblem problem = Perturb(truth, 7, 0.02, 0.1);
  const Errors before = Compare(problem, truth);

  const BundleAdjustmentSummary summary = SolveBundleAdjustment({}, &problem);
  ASSERT_TRUE(summary.success) << summary.message;
  const Errors after = Compare(problem, truth);
  SCOPED_TRACE(summary.BriefReport());
  // Before: poses off by several centimetres and degrees, points by ~15 cm.
  EXPECT_GT(before.max_position_m, 0.03);
  EXPECT_GT(before.median_point_m, 0.1);
  // After: with 0.5 px noise the remaining error is the estimation noise, millimetres.
  EXPECT_LT(after.max_position_m, 0.005);
  EXPECT_LT(after.max_angle_rad, 0.001);
  EXPECT_LT(after.median_point_m, 0.02);
  // The residual is the noise minus what the fit absorbs: E[rms^2] = sigma^2 * 2 (m - n) / m
  // for m scalar residuals and n free parameters (3 per point, 6 per free pose).
  const double m = 2.0 * truth.observations.size();
  const double n = 3.0 * truth.points.size() + 6.0 * (truth.poses.size() - 2);
  const double expected_rms = 0.5 * std::sqrt(2.0 * (m - n) / m);
  EXPECT_NEAR(summary.final_rms_px, expected_rms, 0.02);
  EXPECT_GT(summary.initial_rms_px, 5.0);
  EXPECT_LT(summary.final_cost, summary.initial_cost);
  // Fixed poses did not move.
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(problem.poses[i].cam_from_world.translation,
              truth.poses[i].cam_from_world.translation);
  }
}

TEST(BundleAdjustmentTest, StopRequestEndsTheSolveWithAUsableIterate) {
  SyntheticSceneOptions scene_options;
  scene_options.noise_px = 0.5;
  const BundleAdjustmentProblem truth = MakeSyntheticScene(scene_options);
  const BundleAdjustmentProblem start = Perturb(truth, 7, 0.02, 0.1);
  BundleAdjustmentProblem full = start;
  BundleAdjustmentProblem stopped = start;
  const BundleAdjustmentSummary full_summary = SolveBundleAdjustment({}, &full);
  ASSERT_TRUE(full_summary.success) << full_summary.message;
  EXPECT_FALSE(full_summary.stopped_early);
  ASSERT_GE(full_summary.num_iterations, 3);

  // Asked after every iteration, it is heeded from the second on: two steps are taken.
  int num_asked = 0;
  BundleAdjustmentOptions options;
  options.min_iterations_before_stop = 2;
  options.stop_requested = [&num_asked] {
    ++num_asked;
    return true;
  };
  const BundleAdjustmentSummary summary = SolveBundleAdjustment(options, &stopped);
  ASSERT_TRUE(summary.success) << summary.message;
  EXPECT_TRUE(summary.stopped_early);
  EXPECT_EQ(summary.num_iterations, 2);
  EXPECT_EQ(num_asked, 1);
  // Two Levenberg-Marquardt steps already took most of the error out; the full solve more.
  EXPECT_LT(summary.final_rms_px, 0.5 * summary.initial_rms_px);
  EXPECT_GT(summary.final_cost, full_summary.final_cost);
  EXPECT_LT(Compare(stopped, truth).median_point_m, Compare(start, truth).median_point_m);

  // A request that never comes changes nothing.
  BundleAdjustmentProblem unasked = start;
  options.stop_requested = [] { return false; };
  const BundleAdjustmentSummary unasked_summary = SolveBundleAdjustment(options, &unasked);
  EXPECT_FALSE(unasked_summary.stopped_early);
  EXPECT_EQ(unasked_summary.num_iterations, full_summary.num_iterations);
  EXPECT_DOUBLE_EQ(unasked_summary.final_cost, full_summary.final_cost);
}

TEST(BundleAdjustmentTest, HuberLossResistsOutliersAndFlagsThem) {
  SyntheticSceneOptions scene_options;
  scene_options.noise_px = 0.5;
  const BundleAdjustmentProblem truth = MakeSyntheticScene(scene_options);
  BundleAdjustmentProblem problem = Perturb(truth, 8, 0.01, 0.05);
  // Move every 50th observation 30 px away: gross mismatches.
  std::vector<bool> corrupted(problem.observations.size(), false);
  for (std::size_t k = 0; k < problem.observations.size(); k += 50) {
    problem.observations[k].pixel += Eigen::Vector2d(30.0, -25.0);
    corrupted[k] = true;
  }
  const BundleAdjustmentSummary summary = SolveBundleAdjustment({}, &problem);
  ASSERT_TRUE(summary.success) << summary.message;
  const Errors after = Compare(problem, truth);
  EXPECT_LT(after.max_position_m, 0.01);
  EXPECT_LT(after.median_point_m, 0.03);
  ASSERT_EQ(summary.outliers.size(), corrupted.size());
  // Points with a corrupted observation may be pulled a little; their other observations
  // can then fail the test. Observations of untouched points must all pass.
  std::vector<bool> point_corrupted(problem.points.size(), false);
  for (std::size_t k = 0; k < corrupted.size(); ++k) {
    if (corrupted[k]) point_corrupted[problem.observations[k].point_index] = true;
  }
  int flagged_corrupted = 0, flagged_clean = 0, flagged_untouched = 0, num_corrupted = 0;
  for (std::size_t k = 0; k < corrupted.size(); ++k) {
    num_corrupted += corrupted[k] ? 1 : 0;
    if (!summary.outliers[k]) continue;
    if (corrupted[k]) {
      ++flagged_corrupted;
    } else {
      ++flagged_clean;
      if (!point_corrupted[problem.observations[k].point_index]) ++flagged_untouched;
    }
  }
  EXPECT_EQ(flagged_corrupted, num_corrupted);
  EXPECT_EQ(summary.num_outliers, flagged_corrupted + flagged_clean);
  // Noise 0.5 px vs threshold sqrt(5.991) px: P(clean fails) ~ 6e-6 per observation.
  EXPECT_EQ(flagged_untouched, 0);
  EXPECT_LT(flagged_clean, num_corrupted / 10);
}

TEST(BundleAdjustmentTest, UnobservedPosesAndPointsStayUnchanged) {
  BundleAdjustmentProblem problem = MakeSyntheticScene({});
  problem.poses[0].fixed = problem.poses[1].fixed = true;
  problem.poses.push_back(
      {Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(9, 9, 9)), false});
  problem.points.push_back({Eigen::Vector3d(1.0, 2.0, 3.0), false});
  const BundleAdjustmentSummary summary = SolveBundleAdjustment({}, &problem);
  ASSERT_TRUE(summary.success);
  EXPECT_EQ(problem.poses.back().cam_from_world.translation, Eigen::Vector3d(9, 9, 9));
  EXPECT_EQ(problem.points.back().p_in_world, Eigen::Vector3d(1.0, 2.0, 3.0));
  // Exact observations at the truth: nothing to improve.
  EXPECT_LT(summary.final_rms_px, 1e-6);
}

}  // namespace
}  // namespace arucoslam
