// ReprojectionError's residual and analytic Jacobians, and ReprojectionCost (the Ceres cost
// both bundle adjustments build on it), each against central differences.
#include "arucoslam/optim/reprojection_error.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

#include "arucoslam/optim/reprojection_cost_ceres.h"

namespace arucoslam {
namespace {

const PinholeIntrinsics kIntrinsics{458.0, 457.0, 367.0, 248.0};

// A random pose, a point 1..6 m in front of it anywhere in a wide field of view, and an
// observation near (300, 200) px.
struct RandomView {
  Rigid3 cam_from_world;
  Eigen::Vector3d p_in_world;
  Eigen::Vector2d observed;
};

RandomView DrawView(std::mt19937& random) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Vector6d tangent;
  for (int k = 0; k < 6; ++k) tangent[k] = unit(random);
  RandomView view;
  view.cam_from_world = Rigid3::Exp(tangent);
  const Eigen::Vector3d p_in_cam(unit(random) * 2.0, unit(random) * 1.5, 3.5 + 2.5 * unit(random));
  view.p_in_world = view.cam_from_world.Inverse() * p_in_cam;
  view.observed = Eigen::Vector2d(300.0 + unit(random), 200.0 + unit(random));
  return view;
}

// Central differences of the residual w.r.t. a left perturbation of the pose.
PoseJacobian NumericPoseJacobian(const ReprojectionError& error, const Rigid3& pose,
                                 const Eigen::Vector3d& point) {
  const double h = 1e-6;
  PoseJacobian jacobian;
  for (int k = 0; k < 6; ++k) {
    Vector6d delta = Vector6d::Zero();
    delta[k] = h;
    Eigen::Vector2d plus, minus;
    EXPECT_TRUE(error.Evaluate(Rigid3::Exp(delta) * pose, point, &plus));
    EXPECT_TRUE(error.Evaluate(Rigid3::Exp(-delta) * pose, point, &minus));
    jacobian.col(k) = (plus - minus) / (2.0 * h);
  }
  return jacobian;
}

PointJacobian NumericPointJacobian(const ReprojectionError& error, const Rigid3& pose,
                                   const Eigen::Vector3d& point) {
  const double h = 1e-6;
  PointJacobian jacobian;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d delta = h * Eigen::Vector3d::Unit(k);
    Eigen::Vector2d plus, minus;
    EXPECT_TRUE(error.Evaluate(pose, point + delta, &plus));
    EXPECT_TRUE(error.Evaluate(pose, point - delta, &minus));
    jacobian.col(k) = (plus - minus) / (2.0 * h);
  }
  return jacobian;
}

TEST(ReprojectionErrorTest, ResidualIsProjectionMinusObservation) {
  const Rigid3 cam_from_world(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, 1.0));
  const Eigen::Vector3d p_in_world(0.5, -0.25, 1.0);  // (0.5, -0.25, 2) in the camera
  const ReprojectionError error(kIntrinsics, Eigen::Vector2d(480.0, 200.0));
  Eigen::Vector2d residual;
  ASSERT_TRUE(error.Evaluate(cam_from_world, p_in_world, &residual));
  EXPECT_NEAR(residual.x(), 458.0 * 0.25 + 367.0 - 480.0, 1e-12);
  EXPECT_NEAR(residual.y(), 457.0 * -0.125 + 248.0 - 200.0, 1e-12);
}

TEST(ReprojectionErrorTest, RejectsPointsBehindTheCamera) {
  const ReprojectionError error(kIntrinsics, Eigen::Vector2d(300.0, 200.0));
  Eigen::Vector2d residual(7.0, 7.0);
  EXPECT_FALSE(error.Evaluate(Rigid3(), Eigen::Vector3d(0.1, 0.1, -2.0), &residual));
  EXPECT_FALSE(error.Evaluate(Rigid3(), Eigen::Vector3d(0.1, 0.1, 0.0), &residual));
  EXPECT_EQ(residual, Eigen::Vector2d(7.0, 7.0));
}

TEST(ReprojectionErrorTest, AnalyticJacobiansMatchNumericDifferences) {
  std::mt19937 random(3);
  for (int trial = 0; trial < 50; ++trial) {
    const auto [cam_from_world, p_in_world, observed] = DrawView(random);
    const ReprojectionError error(kIntrinsics, observed);
    Eigen::Vector2d residual;
    PoseJacobian d_pose;
    PointJacobian d_point;
    ASSERT_TRUE(error.Evaluate(cam_from_world, p_in_world, &residual, &d_pose, &d_point));
    const PoseJacobian numeric_pose = NumericPoseJacobian(error, cam_from_world, p_in_world);
    const PointJacobian numeric_point = NumericPointJacobian(error, cam_from_world, p_in_world);
    // Entries are up to ~500 px per unit; central differences are good to ~1e-6 here.
    EXPECT_LT((d_pose - numeric_pose).cwiseAbs().maxCoeff(), 1e-5 * (1.0 + numeric_pose.norm()))
        << "trial " << trial << "\nanalytic\n"
        << d_pose << "\nnumeric\n"
        << numeric_pose;
    EXPECT_LT((d_point - numeric_point).cwiseAbs().maxCoeff(), 1e-5 * (1.0 + numeric_point.norm()))
        << "trial " << trial;
  }
}

namespace ceres_cost {

using ceres_internal::kPoseSize;
using ceres_internal::kPoseTangentSize;
using ceres_internal::PoseBlock;
using ceres_internal::PoseToBlock;
using ceres_internal::ReprojectionCost;
using PoseBlockJacobian = Eigen::Matrix<double, 2, kPoseSize, Eigen::RowMajor>;
using PointBlockJacobian = Eigen::Matrix<double, 2, 3, Eigen::RowMajor>;

struct Evaluation {
  Eigen::Vector2d residual;
  PoseBlockJacobian d_pose;
  PointBlockJacobian d_point;
};

Evaluation Evaluate(const ReprojectionCost& cost, const PoseBlock& pose,
                    const Eigen::Vector3d& point) {
  Evaluation evaluation;
  const double* parameters[2] = {pose.data(), point.data()};
  double* jacobians[2] = {evaluation.d_pose.data(), evaluation.d_point.data()};
  EXPECT_TRUE(cost.Evaluate(parameters, evaluation.residual.data(), jacobians));
  return evaluation;
}

Eigen::Vector2d Residual(const ReprojectionCost& cost, const PoseBlock& pose,
                         const Eigen::Vector3d& point) {
  Eigen::Vector2d residual;
  const double* parameters[2] = {pose.data(), point.data()};
  EXPECT_TRUE(cost.Evaluate(parameters, residual.data(), nullptr));
  return residual;
}

TEST(ReprojectionCostTest, ResidualIsReprojectionErrorOverSigma) {
  const Rigid3 cam_from_world(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, 1.0));
  const Eigen::Vector3d p_in_world(0.5, -0.25, 1.0);  // (0.5, -0.25, 2) in the camera
  const ReprojectionCost cost(kIntrinsics, Eigen::Vector2d(480.0, 200.0), 2.0);
  const Eigen::Vector2d residual = Residual(cost, PoseToBlock(cam_from_world), p_in_world);
  EXPECT_NEAR(residual.x(), (458.0 * 0.25 + 367.0 - 480.0) / 2.0, 1e-12);
  EXPECT_NEAR(residual.y(), (457.0 * -0.125 + 248.0 - 200.0) / 2.0, 1e-12);
}

// Costs handed out by the store are distinct, each with its own observation, and stay valid
// (the store never reallocates) until it is full; one more is refused.
TEST(ReprojectionCostTest, StoreHandsOutStableCostsUpToItsCapacity) {
  const Rigid3 cam_from_world(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, 1.0));
  const Eigen::Vector3d p_in_world(0.5, -0.25, 1.0);  // projects to (481.5, 190.875) px
  constexpr int kCapacity = 40;
  ceres_internal::ReprojectionCosts costs(kCapacity);
  std::vector<ReprojectionCost*> handed;
  for (int i = 0; i < kCapacity; ++i) {
    handed.push_back(costs.Add(kIntrinsics, Eigen::Vector2d(480.0 - i, 200.0), 1.0 + i));
  }
  for (int i = 0; i < kCapacity; ++i) {
    const Eigen::Vector2d residual = Residual(*handed[i], PoseToBlock(cam_from_world), p_in_world);
    EXPECT_NEAR(residual.x(), (458.0 * 0.25 + 367.0 - (480.0 - i)) / (1.0 + i), 1e-12) << i;
    EXPECT_NEAR(residual.y(), (457.0 * -0.125 + 248.0 - 200.0) / (1.0 + i), 1e-12) << i;
  }
  EXPECT_THROW(costs.Add(kIntrinsics, Eigen::Vector2d(480.0, 200.0), 1.0), std::out_of_range);
}

TEST(ReprojectionCostTest, PointBehindTheCameraGivesNoInformation) {
  const ReprojectionCost cost(kIntrinsics, Eigen::Vector2d(300.0, 200.0), 1.0);
  const Evaluation evaluation =
      Evaluate(cost, PoseToBlock(Rigid3()), Eigen::Vector3d(0.1, 0.1, -2.0));
  EXPECT_EQ(evaluation.residual, Eigen::Vector2d::Zero());
  EXPECT_EQ(evaluation.d_pose, PoseBlockJacobian::Zero());
  EXPECT_EQ(evaluation.d_point, PointBlockJacobian::Zero());
}

// Ceres' tangent Jacobian is the block Jacobian times PlusJacobian ([I6; 0]): the first six
// columns against differences through the manifold's Plus, the seventh zero.
TEST(ReprojectionCostTest, JacobiansMatchNumericDifferencesOnTheManifold) {
  std::mt19937 random(5);
  const ceres_internal::Se3LeftManifold manifold;
  const double h = 1e-6;
  for (int trial = 0; trial < 30; ++trial) {
    const auto [cam_from_world, p_in_world, observed] = DrawView(random);
    const double sigma_px = 1.0 + 0.1 * trial;
    const ReprojectionCost cost(kIntrinsics, observed, sigma_px);
    const PoseBlock pose = PoseToBlock(cam_from_world);
    const Evaluation evaluation = Evaluate(cost, pose, p_in_world);
    EXPECT_EQ(evaluation.d_pose.col(kPoseTangentSize), Eigen::Vector2d::Zero());

    Eigen::Matrix<double, 2, kPoseTangentSize> numeric_pose;
    for (int k = 0; k < kPoseTangentSize; ++k) {
      const Vector6d delta = h * Vector6d::Unit(k);
      const Vector6d negative = -delta;
      PoseBlock plus, minus;
      manifold.Plus(pose.data(), delta.data(), plus.data());
      manifold.Plus(pose.data(), negative.data(), minus.data());
      numeric_pose.col(k) =
          (Residual(cost, plus, p_in_world) - Residual(cost, minus, p_in_world)) / (2.0 * h);
    }
    Eigen::Matrix<double, 2, 3> numeric_point;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d delta = h * Eigen::Vector3d::Unit(k);
      numeric_point.col(k) =
          (Residual(cost, pose, p_in_world + delta) - Residual(cost, pose, p_in_world - delta)) /
          (2.0 * h);
    }
    const Eigen::Matrix<double, 2, kPoseTangentSize> analytic_pose =
        evaluation.d_pose.leftCols<kPoseTangentSize>();
    EXPECT_LT((analytic_pose - numeric_pose).cwiseAbs().maxCoeff(),
              1e-5 * (1.0 + numeric_pose.norm()))
        << "trial " << trial;
    EXPECT_LT((evaluation.d_point - numeric_point).cwiseAbs().maxCoeff(),
              1e-5 * (1.0 + numeric_point.norm()))
        << "trial " << trial;
  }
}

}  // namespace ceres_cost
}  // namespace
}  // namespace arucoslam
