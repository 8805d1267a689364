#include "arucoslam/optim/pose_optimizer.h"

#include <gtest/gtest.h>

#include <random>

namespace arucoslam {
namespace {

const PinholeIntrinsics kIntrinsics{500.0, 500.0, 319.5, 239.5};

struct Scene {
  Rigid3 cam_from_world;
  std::vector<PoseObservation> observations;
  std::vector<bool> is_outlier;
};

// `num_points` points 2..10 m in front of a known pose, pixels with 0.5 px noise; a
// fraction of them replaced by pixels far from their true projection.
Scene MakeScene(int num_points, double outlier_fraction, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> depth(2.0, 10.0);
  std::uniform_real_distribution<double> coin(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.5);
  Scene scene;
  scene.cam_from_world =
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized())),
             Eigen::Vector3d(0.3, -0.2, 1.0));
  const Rigid3 world_from_cam = scene.cam_from_world.Inverse();
  for (int i = 0; i < num_points; ++i) {
    const double z = depth(random);
    const Eigen::Vector3d p_in_cam(unit(random) * 0.6 * z, unit(random) * 0.45 * z, z);
    PoseObservation observation;
    observation.p_in_world = world_from_cam * p_in_cam;
    observation.pixel =
        kIntrinsics.ToPixel(p_in_cam.head<2>() / z) + Eigen::Vector2d(noise(random), noise(random));
    observation.sigma_px = 1.0;
    const bool outlier = coin(random) < outlier_fraction;
    if (outlier) {
      // At least 20 px away from the truth, in a random direction.
      const double angle = 3.14159 * unit(random);
      observation.pixel +=
          (20.0 + 60.0 * coin(random)) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    }
    scene.observations.push_back(observation);
    scene.is_outlier.push_back(outlier);
  }
  return scene;
}

double PositionError(const Rigid3& a, const Rigid3& b) {
  return (a.Inverse().translation - b.Inverse().translation).norm();
}
double AngleErrorDegrees(const Rigid3& a, const Rigid3& b) {
  return RotationAngle(a.rotation.conjugate() * b.rotation) * 180.0 / 3.14159265358979;
}

TEST(PoseOptimizerTest, OptionsCheck) {
  EXPECT_TRUE(PoseOptimizationOptions{}.Check());
  PoseOptimizationOptions options;
  options.chi_square_threshold = 0.0;
  EXPECT_FALSE(options.Check());
}

TEST(PoseOptimizerTest, ConvergesToTruthAndFlagsOutliers) {
  const Scene scene = MakeScene(300, 0.2, 11);
  // Start 10 cm and 3 degrees away from the truth.
  Vector6d perturbation;
  perturbation << 0.06, -0.05, 0.06, 0.03, -0.03, 0.025;
  const Rigid3 initial = Rigid3::Exp(perturbation) * scene.cam_from_world;
  ASSERT_GT(PositionError(initial, scene.cam_from_world), 0.08);
  ASSERT_GT(AngleErrorDegrees(initial, scene.cam_from_world), 2.5);

  const PoseOptimizationResult result =
      OptimizePose(scene.observations, initial, kIntrinsics, PoseOptimizationOptions{});
  ASSERT_TRUE(result.success);
  // 240 inliers with 0.5 px noise at 2..10 m: the pose is good to a few millimetres.
  EXPECT_LT(PositionError(result.cam_from_world, scene.cam_from_world), 0.01);
  EXPECT_LT(AngleErrorDegrees(result.cam_from_world, scene.cam_from_world), 0.1);
  EXPECT_LT(result.final_rms_px, 1.0);
  EXPECT_GT(result.initial_rms_px, 10.0);

  int true_outliers_flagged = 0, num_outliers = 0, inliers_kept = 0, num_inliers = 0;
  ASSERT_EQ(result.inliers.size(), scene.observations.size());
  for (std::size_t i = 0; i < scene.is_outlier.size(); ++i) {
    if (scene.is_outlier[i]) {
      ++num_outliers;
      true_outliers_flagged += result.inliers[i] ? 0 : 1;
    } else {
      ++num_inliers;
      inliers_kept += result.inliers[i] ? 1 : 0;
    }
  }
  // Outliers are >= 20 px off: every one must be rejected. Inliers: chi-square at 95% with
  // sigma 1 and noise 0.5 px keeps virtually all (P(|r|^2 > 5.991 * 4 sigma^2) ~ 6e-6).
  EXPECT_EQ(true_outliers_flagged, num_outliers);
  EXPECT_EQ(inliers_kept, num_inliers);
  EXPECT_EQ(result.num_inliers, num_inliers);
}

TEST(PoseOptimizerTest, ReportsFailureWithTooFewObservations) {
  Scene scene = MakeScene(8, 0.0, 5);
  const PoseOptimizationResult result =
      OptimizePose(scene.observations, scene.cam_from_world, kIntrinsics, {});
  EXPECT_FALSE(result.success);  // 8 < min_inliers (10)
  EXPECT_EQ(result.num_inliers, 8);
}

TEST(PoseOptimizerTest, FailsWhenEveryObservationIsAnOutlier) {
  const Scene scene = MakeScene(100, 1.0, 9);  // every pixel >= 20 px off
  const PoseOptimizationResult result =
      OptimizePose(scene.observations, scene.cam_from_world, kIntrinsics, {});
  EXPECT_FALSE(result.success);
  EXPECT_LT(result.num_inliers, 10);
}

}  // namespace
}  // namespace arucoslam
