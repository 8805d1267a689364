// The radial term of SolveBundleAdjustmentWithRadialTerm: its cost's Jacobians against central
// differences, the coefficient recovered from a synthetic scene observed through a radial
// distortion the calibration lacks, and its folding into a camera model.
#include "arucoslam/optim/radial_refinement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arucoslam/optim/radial_reprojection_cost_ceres.h"
#include "arucoslam/optim/synthetic_scene.h"

namespace arucoslam {
namespace {

using ceres_internal::kPoseSize;
using ceres_internal::kPoseTangentSize;
using ceres_internal::PoseBlock;
using ceres_internal::PoseToBlock;
using ceres_internal::RadialReprojectionCost;

const PinholeIntrinsics kIntrinsics{707.0, 705.0, 601.0, 183.0};

Eigen::Vector2d Residual(const RadialReprojectionCost& cost, const PoseBlock& pose,
                         const Eigen::Vector3d& point, double k,
                         Eigen::Matrix<double, 2, kPoseSize, Eigen::RowMajor>* d_pose = nullptr,
                         Eigen::Matrix<double, 2, 3, Eigen::RowMajor>* d_point = nullptr,
                         Eigen::Vector2d* d_k = nullptr) {
  const double* parameters[] = {pose.data(), point.data(), &k};
  double* jacobians[] = {d_pose ? d_pose->data() : nullptr, d_point ? d_point->data() : nullptr,
                         d_k ? d_k->data() : nullptr};
  Eigen::Vector2d residual;
  cost.Evaluate(parameters, residual.data(), d_pose ? jacobians : nullptr);
  return residual;
}

TEST(RadialReprojectionCostTest, JacobiansMatchNumericDifferences) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const ceres_internal::Se3LeftManifold manifold;
  const double h = 1e-6;
  for (int trial = 0; trial < 30; ++trial) {
    Vector6d tangent;
    for (int i = 0; i < 6; ++i) tangent[i] = 0.5 * unit(random);
    const Rigid3 cam_from_world = Rigid3::Exp(tangent);
    // Points across a wide field of view, where the radial term is large.
    const Eigen::Vector3d p_in_cam(6.0 * unit(random), 2.0 * unit(random), 8.0 + 3.0 * unit(random));
    const Eigen::Vector3d point = cam_from_world.Inverse() * p_in_cam;
    const double k = 0.05 * unit(random);
    const RadialReprojectionCost cost(kIntrinsics, Eigen::Vector2d(500.0, 200.0), 1.2);
    const PoseBlock pose = PoseToBlock(cam_from_world);
    Eigen::Matrix<double, 2, kPoseSize, Eigen::RowMajor> d_pose;
    Eigen::Matrix<double, 2, 3, Eigen::RowMajor> d_point;
    Eigen::Vector2d d_k;
    Residual(cost, pose, point, k, &d_pose, &d_point, &d_k);
    EXPECT_EQ(d_pose.col(kPoseTangentSize), Eigen::Vector2d::Zero());
    for (int i = 0; i < kPoseTangentSize; ++i) {
      const Vector6d delta = h * Vector6d::Unit(i);
      const Vector6d negative = -delta;
      PoseBlock plus, minus;
      manifold.Plus(pose.data(), delta.data(), plus.data());
      manifold.Plus(pose.data(), negative.data(), minus.data());
      const Eigen::Vector2d numeric =
          (Residual(cost, plus, point, k) - Residual(cost, minus, point, k)) / (2.0 * h);
      EXPECT_LT((d_pose.col(i) - numeric).norm(), 1e-4 * (1.0 + numeric.norm())) << trial;
    }
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d delta = h * Eigen::Vector3d::Unit(i);
      const Eigen::Vector2d numeric =
          (Residual(cost, pose, point + delta, k) - Residual(cost, pose, point - delta, k)) /
          (2.0 * h);
      EXPECT_LT((d_point.col(i) - numeric).norm(), 1e-4 * (1.0 + numeric.norm())) << trial;
    }
    const Eigen::Vector2d numeric_k =
        (Residual(cost, pose, point, k + h) - Residual(cost, pose, point, k - h)) / (2.0 * h);
    EXPECT_LT((d_k - numeric_k).norm(), 1e-4 * (1.0 + numeric_k.norm())) << trial;
  }
}

// Observations warped by x (1 + k |x|^2) in normalised coordinates.
void WarpObservations(double k, BundleAdjustmentProblem* problem) {
  const PinholeIntrinsics& c = problem->intrinsics;
  for (auto& observation : problem->observations) {
    const Eigen::Vector2d x((observation.pixel.x() - c.cx) / c.fx, (observation.pixel.y() - c.cy) / c.fy);
    const Eigen::Vector2d warped = x * (1.0 + k * x.squaredNorm());
    observation.pixel = Eigen::Vector2d(c.cx + c.fx * warped.x(), c.cy + c.fy * warped.y());
  }
}

BundleAdjustmentProblem WideScene(double noise_px) {
  SyntheticSceneOptions options;
  options.num_points = 800;
  options.noise_px = noise_px;
  options.focal_px = 300.0;  // a wide field of view: |x| up to about 1
  options.seed = 7;
  BundleAdjustmentProblem problem = MakeSyntheticScene(options);
  for (std::size_t i = 0; i < problem.poses.size(); ++i) problem.poses[i].fixed = i < 2;
  return problem;
}

TEST(RadialRefinementTest, RecoversTheRadialCoefficientTheCalibrationLacks) {
  for (const double k_true : {0.03, -0.02}) {
    BundleAdjustmentProblem problem = WideScene(0.3);
    WarpObservations(k_true, &problem);
    BundleAdjustmentOptions options;
    options.max_iterations = 50;
    const RadialRefinementSummary summary = SolveBundleAdjustmentWithRadialTerm(options, &problem);
    ASSERT_TRUE(summary.solve.success) << summary.solve.message;
    EXPECT_NEAR(summary.k, k_true, 0.002) << "k_true " << k_true;
    EXPECT_LT(summary.solve.final_cost, 0.2 * summary.solve.initial_cost);
  }
}

TEST(RadialRefinementTest, FindsNoTermInPinholeObservations) {
  BundleAdjustmentProblem problem = WideScene(0.3);
  BundleAdjustmentOptions options;
  options.max_iterations = 50;
  const RadialRefinementSummary summary = SolveBundleAdjustmentWithRadialTerm(options, &problem);
  ASSERT_TRUE(summary.solve.success);
  EXPECT_LT(std::abs(summary.k), 0.002);
}

TEST(RadialRefinementTest, FoldsTheTermIntoTheCameraModel) {
  CameraModel pinhole = PinholeCamera(640, 480, 300.0);
  const std::optional<CameraModel> radial = WithRadialTerm(pinhole, 0.03);
  ASSERT_TRUE(radial.has_value());
  EXPECT_EQ(radial->model, DistortionModel::kRadTan);
  EXPECT_DOUBLE_EQ(radial->distortion[0], 0.03);
  // The refined camera undistorts a pixel warped by the term back to the pinhole ray.
  const Eigen::Vector2d ideal(0.6, -0.4);
  const Eigen::Vector2d warped = ideal * (1.0 + 0.03 * ideal.squaredNorm());
  const Eigen::Vector2d pixel(pinhole.cx + pinhole.fx * warped.x(), pinhole.cy + pinhole.fy * warped.y());
  EXPECT_LT((radial->Unproject(pixel) - ideal).norm(), 1e-9);

  CameraModel fisheye = pinhole;
  fisheye.model = DistortionModel::kEquidistant;
  EXPECT_FALSE(WithRadialTerm(fisheye, 0.03).has_value());
}

}  // namespace
}  // namespace arucoslam
