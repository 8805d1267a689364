#include "arucoslam/optim/vehicle_motion_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

namespace arucoslam {
namespace {

// A level camera at `centre` looking along heading `yaw` (world z up; camera x right, y down).
Rigid3 VehicleCamera(const Eigen::Vector3d& centre, double yaw) {
  Eigen::Matrix3d world_from_cam;
  world_from_cam.col(0) = Eigen::Vector3d(std::sin(yaw), -std::cos(yaw), 0.0);
  world_from_cam.col(1) = Eigen::Vector3d(0.0, 0.0, -1.0);
  world_from_cam.col(2) = Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);
  return Rigid3(Eigen::Quaterniond(world_from_cam), centre).Inverse();
}

// The camera driven forwards on a circle of radius `radius` at `speed`, at time t.
Rigid3 OnArc(double radius, double speed, double t) {
  const double angle = speed * t / radius;
  return VehicleCamera({radius * std::sin(angle), radius * (1.0 - std::cos(angle)), 0.6}, angle);
}

TEST(VehicleMotionErrorTest, ZeroWhenDrivingForwardsOnAnArcAtConstantSpeed) {
  const VehicleMotionPriorOptions options;
  const LateralVelocityError lateral(options, 0.4);
  double residual = 1.0;
  lateral.Evaluate(OnArc(2.0, 0.8, 1.0), OnArc(2.0, 0.8, 1.4), &residual);
  EXPECT_NEAR(residual, 0.0, 1e-12);
  // Unequal intervals: the forward speeds (chord over time, seen from both ends) are equal.
  const ForwardSpeedChangeError speed(options, 0.3, 0.7);
  speed.Evaluate(OnArc(2.0, 0.8, 0.0), OnArc(2.0, 0.8, 0.3), OnArc(2.0, 0.8, 1.0), &residual);
  // Seen from both ends a chord of angle a on radius r has forward length r sin(a): the
  // speeds differ only by the chords' shortening, 0.0085 m/s or 0.05 sigma here.
  const auto chord_speed = [](double dt) { return 2.0 * std::sin(0.8 * dt / 2.0) / dt; };
  EXPECT_NEAR(residual, (chord_speed(0.7) - chord_speed(0.3)) / std::sqrt(0.1 * 1.0 / 3.0), 1e-9);
  EXPECT_LT(std::abs(residual), 0.06);
}

TEST(VehicleMotionErrorTest, WhitenedSidewaysSpeedAndSpeedChange) {
  const VehicleMotionPriorOptions options{0.05, 0.1, 2.0};
  // Heading +x, moving 0.1 m to the left (+y) in 0.5 s: 0.2 m/s sideways, x points right.
  const LateralVelocityError lateral(options, 0.5);
  double residual = 0.0;
  lateral.Evaluate(VehicleCamera({0, 0, 0.6}, 0.0), VehicleCamera({0, 0.1, 0.6}, 0.0), &residual);
  EXPECT_NEAR(residual, -0.2 / 0.05, 1e-9);
  // Forward 1 m/s then 1.2 m/s over 0.5 s each: 0.2 / sqrt(0.1 * 1.0 / 3) sigmas.
  const ForwardSpeedChangeError speed(options, 0.5, 0.5);
  speed.Evaluate(VehicleCamera({0, 0, 0}, 0.0), VehicleCamera({0.5, 0, 0}, 0.0),
                 VehicleCamera({1.1, 0, 0}, 0.0), &residual);
  EXPECT_NEAR(residual, 0.2 / std::sqrt(0.1 / 3.0), 1e-9);
}

// Central differences of `evaluate` over the left perturbation of pose `which`, column k.
double NumericDerivative(const std::function<double(const Rigid3*)>& evaluate, const Rigid3* poses,
                         int count, int which, int k) {
  const double h = 1e-6;
  Vector6d delta = Vector6d::Zero();
  delta[k] = h;
  Rigid3 plus[3], minus[3];
  for (int i = 0; i < count; ++i) plus[i] = minus[i] = poses[i];
  plus[which] = Rigid3::Exp(delta) * poses[which];
  minus[which] = Rigid3::Exp(-delta) * poses[which];
  return (evaluate(plus) - evaluate(minus)) / (2.0 * h);
}

TEST(VehicleMotionErrorTest, AnalyticJacobiansMatchNumericDifferences) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const VehicleMotionPriorOptions options{0.05, 0.3, 2.0};
  const LateralVelocityError lateral(options, 0.3);
  const ForwardSpeedChangeError speed(options, 0.3, 0.7);
  for (int trial = 0; trial < 20; ++trial) {
    Rigid3 poses[3];
    for (Rigid3& pose : poses) {
      Vector6d tangent;
      for (int k = 0; k < 6; ++k) tangent[k] = 2.0 * uniform(random);
      pose = Rigid3::Exp(tangent);
    }
    double residual;
    VehicleMotionPoseJacobian j[3];
    lateral.Evaluate(poses[0], poses[1], &residual, &j[0], &j[1]);
    const auto lateral_of = [&](const Rigid3* p) {
      double r;
      lateral.Evaluate(p[0], p[1], &r);
      return r;
    };
    for (int which = 0; which < 2; ++which) {
      for (int k = 0; k < 6; ++k) {
        EXPECT_NEAR(NumericDerivative(lateral_of, poses, 2, which, k), j[which](k),
                    1e-5 * (1.0 + std::abs(j[which](k))))
            << "lateral, pose " << which << " column " << k;
      }
    }
    speed.Evaluate(poses[0], poses[1], poses[2], &residual, &j[0], &j[1], &j[2]);
    const auto speed_of = [&](const Rigid3* p) {
      double r;
      speed.Evaluate(p[0], p[1], p[2], &r);
      return r;
    };
    for (int which = 0; which < 3; ++which) {
      for (int k = 0; k < 6; ++k) {
        EXPECT_NEAR(NumericDerivative(speed_of, poses, 3, which, k), j[which](k),
                    1e-5 * (1.0 + std::abs(j[which](k))))
            << "speed, pose " << which << " column " << k;
      }
    }
  }
}

}  // namespace
}  // namespace arucoslam
