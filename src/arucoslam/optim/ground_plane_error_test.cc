#include "arucoslam/optim/ground_plane_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace arucoslam {
namespace {

// A forward-looking camera (OpenCV axes: y down, z ahead) at `height` on a z-up world,
// heading `yaw` about world z, pitched down by `pitch`.
Rigid3 GroundCamera(double x, double y, double height, double yaw, double pitch) {
  Eigen::Matrix3d world_from_level;  // camera x right, y down, z ahead for yaw 0 (ahead = +x)
  world_from_level << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Eigen::Matrix3d world_from_cam =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * world_from_level *
      Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return Rigid3(Eigen::Quaterniond(world_from_cam), Eigen::Vector3d(x, y, height)).Inverse();
}

const GroundPlanePriorOptions kOptions{0.02, 0.01};

TEST(GroundPlaneErrorTest, ZeroOnThePlaneAndWhitenedOffIt) {
  const GroundPlaneError error(kOptions);
  const GroundPlane plane{0.6, Eigen::Vector3d(0.0, -1.0, 0.0)};
  Eigen::Vector3d residual;
  error.Evaluate(GroundCamera(3.0, -2.0, 0.6, 1.1, 0.0), plane, &residual);
  EXPECT_LT(residual.norm(), 1e-12);
  // 5 cm too high: 2.5 sigmas in the height residual alone.
  error.Evaluate(GroundCamera(3.0, -2.0, 0.65, 1.1, 0.0), plane, &residual);
  EXPECT_NEAR(residual.x(), 2.5, 1e-9);
  EXPECT_NEAR(residual.tail<2>().norm(), 0.0, 1e-12);
  // Pitched down 0.02 rad: the tilt residual is sin(0.02) / 0.01, whatever the heading.
  for (const double yaw : {0.0, 0.7, -2.5}) {
    error.Evaluate(GroundCamera(0.0, 0.0, 0.6, yaw, 0.02), plane, &residual);
    EXPECT_NEAR(residual.x(), 0.0, 1e-12);
    EXPECT_NEAR(residual.tail<2>().norm(), std::sin(0.02) / 0.01, 1e-9);
  }
}

TEST(GroundPlaneErrorTest, AnalyticJacobiansMatchNumericDifferences) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const GroundPlaneError error(kOptions);
  for (int trial = 0; trial < 20; ++trial) {
    Vector6d tangent;
    for (int k = 0; k < 6; ++k) tangent[k] = 2.0 * uniform(random);
    const Rigid3 pose = Rigid3::Exp(tangent);
    GroundPlane plane{0.5 + 0.3 * uniform(random),
                      Eigen::Vector3d(uniform(random), uniform(random), uniform(random))};
    plane.up_in_camera.normalize();

    Eigen::Vector3d residual;
    GroundPlanePoseJacobian d_pose;
    GroundPlaneHeightJacobian d_height;
    GroundPlaneUpJacobian d_up;
    error.Evaluate(pose, plane, &residual, &d_pose, &d_height, &d_up);

    const double h = 1e-6;
    Eigen::Vector3d plus, minus;
    for (int k = 0; k < 6; ++k) {
      Vector6d delta = Vector6d::Zero();
      delta[k] = h;
      error.Evaluate(Rigid3::Exp(delta) * pose, plane, &plus);
      error.Evaluate(Rigid3::Exp(-delta) * pose, plane, &minus);
      EXPECT_LT(((plus - minus) / (2.0 * h) - d_pose.col(k)).norm(), 1e-5) << "pose " << k;
    }
    GroundPlane shifted = plane;
    shifted.height_m += h;
    error.Evaluate(pose, shifted, &plus);
    shifted.height_m -= 2.0 * h;
    error.Evaluate(pose, shifted, &minus);
    EXPECT_LT(((plus - minus) / (2.0 * h) - d_height).norm(), 1e-5);
    for (int k = 0; k < 3; ++k) {
      shifted = plane;
      shifted.up_in_camera[k] += h;
      error.Evaluate(pose, shifted, &plus);
      shifted.up_in_camera[k] -= 2.0 * h;
      error.Evaluate(pose, shifted, &minus);
      EXPECT_LT(((plus - minus) / (2.0 * h) - d_up.col(k)).norm(), 1e-5) << "up " << k;
    }
  }
}

TEST(GroundPlaneErrorTest, MeanPlaneOfCamerasOnTheFloor) {
  const std::vector<Rigid3> poses = {GroundCamera(0, 0, 0.58, 0.0, 0.01),
                                     GroundCamera(4, 1, 0.62, 1.5, -0.01),
                                     GroundCamera(-2, 3, 0.60, -2.0, 0.0)};
  const GroundPlane plane = MeanGroundPlane(poses);
  EXPECT_NEAR(plane.height_m, 0.60, 1e-12);
  EXPECT_NEAR(plane.up_in_camera.norm(), 1.0, 1e-12);
  EXPECT_LT((plane.up_in_camera - Eigen::Vector3d(0, -1, 0)).norm(), 0.01);
  EXPECT_EQ(MeanGroundPlane({}).up_in_camera, Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace arucoslam
