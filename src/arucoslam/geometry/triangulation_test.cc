#include "arucoslam/geometry/triangulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace arucoslam {
namespace {

Eigen::Vector2d Normalised(const Eigen::Vector3d& p_in_cam) { return p_in_cam.hnormalized(); }

TEST(Triangulation, ExactObservationsGiveThePoint) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Rigid3 cam1_from_world(ExpSO3(Eigen::Vector3d(0.1, -0.2, 0.05)),
                               Eigen::Vector3d(0.3, -0.1, 0.2));
  const Rigid3 cam2_from_world =
      Rigid3(ExpSO3(Eigen::Vector3d(-0.05, 0.1, 0.0)), Eigen::Vector3d(-0.5, 0.0, 0.1)) *
      cam1_from_world;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d p_in_cam1(2.0 * unit(rng), 1.5 * unit(rng), 5.0 + 2.0 * unit(rng));
    const Eigen::Vector3d p_in_world = cam1_from_world.Inverse() * p_in_cam1;
    const auto point = TriangulateDlt(cam1_from_world, cam2_from_world, Normalised(p_in_cam1),
                                      Normalised(cam2_from_world * p_in_world));
    ASSERT_TRUE(point.has_value());
    EXPECT_LT((*point - p_in_world).norm(), 1e-9 * p_in_world.norm());
  }
}

TEST(Triangulation, NoisyObservationsErrorGrowsWithDepthAsExpected) {
  // Baseline 0.5 m, f = 500 px, 0.5 px noise: depth error ~ z^2 / (f b) * sigma * sqrt(2),
  // i.e. about 0.14 m at z = 5 m. The median error must be within 2x of that.
  std::mt19937 rng(12);
  std::normal_distribution<double> noise(0.0, 0.5 / 500.0);
  const Rigid3 cam1_from_world;
  const Rigid3 cam2_from_world(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.5, 0.0, 0.0));
  std::vector<double> errors;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d p(0.1 * (i % 7), -0.1 * (i % 5), 5.0);
    const Eigen::Vector2d n1 = Normalised(p) + Eigen::Vector2d(noise(rng), noise(rng));
    const Eigen::Vector2d n2 =
        Normalised(cam2_from_world * p) + Eigen::Vector2d(noise(rng), noise(rng));
    const auto point = TriangulateDlt(cam1_from_world, cam2_from_world, n1, n2);
    ASSERT_TRUE(point.has_value());
    errors.push_back((*point - p).norm());
  }
  std::nth_element(errors.begin(), errors.begin() + 200, errors.end());
  const double expected_sigma = 25.0 / (500.0 * 0.5) * 0.5 * std::sqrt(2.0);
  EXPECT_LT(errors[200], 2.0 * expected_sigma);
  EXPECT_GT(errors[200], 0.2 * expected_sigma);
}

TEST(Triangulation, ParallaxAngleOfKnownGeometry) {
  EXPECT_NEAR(
      ParallaxAngle(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(1, 0, 0)),
      M_PI / 2.0, 1e-12);
  // Tiny angles stay accurate: baseline 1 mm at 100 m -> 1e-5 rad.
  EXPECT_NEAR(ParallaxAngle(Eigen::Vector3d(0, 0, 100), Eigen::Vector3d(-0.0005, 0, 0),
                            Eigen::Vector3d(0.0005, 0, 0)),
              1e-5, 1e-12);
}

TEST(Triangulation, QualityReportsDepthsAndPixelErrors) {
  const Rigid3 cam1_from_world;
  const Rigid3 cam2_from_world(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-1.0, 0.0, 0.0));
  const Eigen::Vector3d p(0.5, 0.2, 4.0);
  // Observation 2 shifted by one pixel in x (fx = 400) and two in y (fy = 500).
  const Eigen::Vector2d n1 = Normalised(p);
  const Eigen::Vector2d n2 =
      Normalised(cam2_from_world * p) + Eigen::Vector2d(1.0 / 400.0, 2.0 / 500.0);
  const TriangulationQuality q =
      EvaluateTriangulation(p, cam1_from_world, cam2_from_world, n1, n2, 400.0, 500.0);
  EXPECT_NEAR(q.depth1, 4.0, 1e-12);
  EXPECT_NEAR(q.depth2, 4.0, 1e-12);
  EXPECT_NEAR(q.error1_sq_px, 0.0, 1e-18);
  EXPECT_NEAR(q.error2_sq_px, 5.0, 1e-9);
  EXPECT_NEAR(q.parallax_rad, ParallaxAngle(p, Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 0)),
              1e-12);
  // Behind camera 1: infinite error and negative depth.
  const TriangulationQuality behind = EvaluateTriangulation(
      Eigen::Vector3d(0.5, 0.2, -4.0), cam1_from_world, cam2_from_world, n1, n2, 400.0, 500.0);
  EXPECT_LT(behind.depth1, 0.0);
  EXPECT_TRUE(std::isinf(behind.error1_sq_px));
}

TEST(Triangulation, ParallelRaysGiveNoFinitePointOrAFarOne) {
  const Rigid3 cam1_from_world;
  const Rigid3 cam2_from_world(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-1.0, 0.0, 0.0));
  const auto point = TriangulateDlt(cam1_from_world, cam2_from_world, Eigen::Vector2d(0.1, 0.2),
                                    Eigen::Vector2d(0.1, 0.2));
  if (point.has_value()) EXPECT_GT(point->norm(), 1e6);
}

}  // namespace
}  // namespace arucoslam
