#include "arucoslam/optim/reprojection_error.h"

#include <gtest/gtest.h>

#include <random>

namespace arucoslam {
namespace {

const PinholeIntrinsics kIntrinsics{458.0, 457.0, 367.0, 248.0};

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
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    Vector6d tangent;
    for (int k = 0; k < 6; ++k) tangent[k] = unit(random);
    const Rigid3 cam_from_world = Rigid3::Exp(tangent);
    // A point 1..6 m in front of the camera, anywhere in a wide field of view.
    const Eigen::Vector3d p_in_cam(unit(random) * 2.0, unit(random) * 1.5,
                                   3.5 + 2.5 * unit(random));
    const Eigen::Vector3d p_in_world = cam_from_world.Inverse() * p_in_cam;
    const ReprojectionError error(kIntrinsics,
                                  Eigen::Vector2d(300.0 + unit(random), 200.0 + unit(random)));
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

}  // namespace
}  // namespace arucoslam
