#include "arucoslam/optim/smooth_motion_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace arucoslam {
namespace {

// A camera whose centre is `centre`, with an arbitrary orientation.
Rigid3 CameraAt(const Eigen::Vector3d& centre, double yaw) {
  const Eigen::Quaterniond world_from_cam(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  return Rigid3(world_from_cam, centre).Inverse();
}

TEST(SmoothMotionErrorTest, ZeroAtConstantVelocityAndWhitenedUnderAcceleration) {
  const SmoothMotionPriorOptions options{0.1, 2.0};
  // Constant velocity (1, 0.5, 0) m/s over unequal intervals, any orientation: no residual.
  const SmoothMotionError uneven(options, 0.2, 0.5);
  Eigen::Vector3d residual;
  uneven.Evaluate(CameraAt({0, 0, 0.6}, 0.3), CameraAt({0.2, 0.1, 0.6}, -1.0),
                  CameraAt({0.7, 0.35, 0.6}, 2.0), &residual);
  EXPECT_LT(residual.norm(), 1e-12);
  // Mean velocity 1 m/s then 1.2 m/s over 0.5 s each: 0.2 / sqrt(0.1 * 1.0 / 3) sigmas.
  const SmoothMotionError even(options, 0.5, 0.5);
  even.Evaluate(CameraAt({0, 0, 0}, 0.0), CameraAt({0.5, 0, 0}, 0.0), CameraAt({1.1, 0, 0}, 0.0),
                &residual);
  EXPECT_NEAR(residual.x(), 0.2 / std::sqrt(0.1 / 3.0), 1e-9);
  EXPECT_NEAR(residual.tail<2>().norm(), 0.0, 1e-12);
}

TEST(SmoothMotionErrorTest, AnalyticJacobiansMatchNumericDifferences) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const SmoothMotionError error({0.3, 2.0}, 0.3, 0.7);
  for (int trial = 0; trial < 20; ++trial) {
    Rigid3 poses[3];
    for (Rigid3& pose : poses) {
      Vector6d tangent;
      for (int k = 0; k < 6; ++k) tangent[k] = 2.0 * uniform(random);
      pose = Rigid3::Exp(tangent);
    }
    Eigen::Vector3d residual;
    SmoothMotionPoseJacobian jacobians[3];
    error.Evaluate(poses[0], poses[1], poses[2], &residual, &jacobians[0], &jacobians[1],
                   &jacobians[2]);
    const double h = 1e-6;
    for (int which = 0; which < 3; ++which) {
      for (int k = 0; k < 6; ++k) {
        Vector6d delta = Vector6d::Zero();
        delta[k] = h;
        Rigid3 plus_poses[3] = {poses[0], poses[1], poses[2]};
        Rigid3 minus_poses[3] = {poses[0], poses[1], poses[2]};
        plus_poses[which] = Rigid3::Exp(delta) * poses[which];
        minus_poses[which] = Rigid3::Exp(-delta) * poses[which];
        Eigen::Vector3d plus, minus;
        error.Evaluate(plus_poses[0], plus_poses[1], plus_poses[2], &plus);
        error.Evaluate(minus_poses[0], minus_poses[1], minus_poses[2], &minus);
        EXPECT_LT(((plus - minus) / (2.0 * h) - jacobians[which].col(k)).norm(), 1e-5)
            << "pose " << which << " column " << k;
      }
    }
  }
}

}  // namespace
}  // namespace arucoslam
