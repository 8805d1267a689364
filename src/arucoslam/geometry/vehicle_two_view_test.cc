#include "arucoslam/geometry/vehicle_two_view.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

namespace arucoslam {
namespace {

constexpr double kDegree = M_PI / 180.0;

TEST(VehicleTwoViewTest, MotionTurnsAboutUpAndMovesAlongTheChord) {
  const Eigen::Vector3d up(0.0, -1.0, 0.0);
  const Rigid3 motion = VehicleMotion(up, 10.0 * kDegree);
  const Rigid3 cam1_from_cam2 = motion.Inverse();
  // Camera 2's centre: unit distance, forwards, turned by half the angle about up.
  const Eigen::Vector3d centre = cam1_from_cam2.translation;
  EXPECT_NEAR(centre.norm(), 1.0, 1e-12);
  EXPECT_NEAR(centre.y(), 0.0, 1e-12);
  EXPECT_NEAR(std::atan2(-centre.x(), centre.z()), 5.0 * kDegree, 1e-12);
  // Its forward axis turned by the whole angle the same way.
  const Eigen::Vector3d forward = cam1_from_cam2.rotation * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(std::atan2(-forward.x(), forward.z()), 10.0 * kDegree, 1e-12);
  EXPECT_NEAR(TwistAngle(cam1_from_cam2.rotation, up), 10.0 * kDegree, 1e-12);
}

TEST(VehicleTwoViewTest, TwistIgnoresTheSwingPart) {
  const Eigen::Vector3d up(0.0, -1.0, 0.0);
  const Eigen::Quaterniond twist(Eigen::AngleAxisd(0.3, up));
  const Eigen::Quaterniond swing(Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX()));
  EXPECT_NEAR(TwistAngle(twist * swing, up), 0.3, 1e-3);
  EXPECT_NEAR(TwistAngle(twist, up), 0.3, 1e-12);
}

// A turning camera (7 degrees over a 0.14 m chord, as a vehicle entering a bend) sees points
// 1.5-8 m away; 0.5 px noise, 10% of the matches wrong. The search recovers the turn.
TEST(VehicleTwoViewTest, RecoversTheTurnOfANarrowBaselinePair) {
  const Eigen::Vector3d up(0.0, -1.0, 0.0);
  const double focal_px = 450.0, angle = 7.0 * kDegree;
  Rigid3 truth = VehicleMotion(up, angle);
  truth.translation *= 0.14;
  std::mt19937 random(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.5 / focal_px);
  std::vector<Eigen::Vector2d> x1, x2;
  while (x1.size() < 120) {
    const Eigen::Vector3d point(3.0 * uniform(random), 1.0 * uniform(random),
                                4.75 + 3.25 * uniform(random));
    const Eigen::Vector3d in2 = truth * point;
    if (in2.z() < 0.5) continue;
    x1.push_back(point.head<2>() / point.z() + Eigen::Vector2d(noise(random), noise(random)));
    x2.push_back(in2.head<2>() / in2.z() + Eigen::Vector2d(noise(random), noise(random)));
    if (x1.size() % 10 == 0) x2.back() += Eigen::Vector2d(0.05, -0.03);  // a wrong match
  }
  const VehicleTwoViewResult result =
      SolveVehicleTwoView(x1, x2, up, angle + 3.0 * kDegree, focal_px);
  EXPECT_NEAR(result.angle_rad, angle, 0.1 * kDegree);
  EXPECT_GE(result.num_inliers, 105);
  const Eigen::Vector3d direction = truth.translation.normalized();
  EXPECT_LT((result.cam2_from_cam1.translation - direction).norm(), 0.01);
}

}  // namespace
}  // namespace arucoslam
