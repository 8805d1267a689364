#include "arucoslam/geometry/sim3.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <unsupported/Eigen/MatrixFunctions>
#include <vector>

namespace arucoslam {
namespace {

constexpr double kPi = std::numbers::pi;

Eigen::Vector3d RandomUnitVector(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
}

// Tangents [upsilon; omega; sigma] over rotation angles and log-scales that reach every
// branch: both small (series), one small, both ordinary, angles near pi.
std::vector<Vector7d> TestTangents(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-3.0, 3.0);
  std::vector<Vector7d> tangents;
  const std::vector<double> angles = {0.0, 1e-10, 1e-7, 1e-4, 9e-3, 1.1e-2, 0.5, 2.0, kPi - 1e-6};
  const std::vector<double> sigmas = {0.0, 1e-10, -1e-7, 1e-4, -9e-3, 1.1e-2, -0.7, 1.5, -2.5};
  for (const double angle : angles) {
    for (const double sigma : sigmas) {
      Vector7d v;
      v.head<3>() = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
      v.segment<3>(3) = angle * RandomUnitVector(rng);
      v(6) = sigma;
      tangents.push_back(v);
    }
  }
  return tangents;
}

Sim3 RandomSim3(std::mt19937& rng) {
  std::uniform_real_distribution<double> uniform(-10.0, 10.0);
  std::uniform_real_distribution<double> angle(0.0, kPi);
  std::uniform_real_distribution<double> log_scale(-2.0, 2.0);
  return Sim3(std::exp(log_scale(rng)),
              Eigen::Quaterniond(Eigen::AngleAxisd(angle(rng), RandomUnitVector(rng))),
              Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)));
}

TEST(Sim3Test, ComposeAndInverseAgreeWithMatrices) {
  std::mt19937 rng(1);
  for (int i = 0; i < 100; ++i) {
    const Sim3 b_from_a = RandomSim3(rng);
    const Sim3 c_from_b = RandomSim3(rng);
    const Eigen::Vector3d p_in_a(0.5, 3.0, -1.25);
    const Sim3 c_from_a = c_from_b * b_from_a;
    EXPECT_TRUE((c_from_a * p_in_a).isApprox(c_from_b * (b_from_a * p_in_a), 1e-12));
    EXPECT_TRUE(c_from_a.ToMatrix().isApprox(c_from_b.ToMatrix() * b_from_a.ToMatrix(), 1e-12));
    EXPECT_TRUE(b_from_a.Inverse().ToMatrix().isApprox(b_from_a.ToMatrix().inverse(), 1e-12));
    const Sim3 identity = b_from_a * b_from_a.Inverse();
    EXPECT_NEAR(identity.scale, 1.0, 1e-14);
    EXPECT_TRUE(identity.ToMatrix().isApprox(Eigen::Matrix4d::Identity(), 1e-12));
  }
}

TEST(Sim3Test, FromRigidAndTransformPose) {
  std::mt19937 rng(2);
  const Rigid3 rigid(Eigen::Quaterniond(Eigen::AngleAxisd(1.0, RandomUnitVector(rng))),
                     Eigen::Vector3d(1.0, -2.0, 0.5));
  const Sim3 from_rigid(rigid);
  EXPECT_EQ(from_rigid.scale, 1.0);
  EXPECT_TRUE(from_rigid.ToMatrix().isApprox(rigid.ToMatrix(), 1e-15));

  // A camera pose world_from_cam in a map frame, moved into the world by a similarity:
  // the camera centre maps like a point and the orientation composes.
  const Sim3 world_from_map = RandomSim3(rng);
  const Rigid3 map_from_cam(Eigen::Quaterniond(Eigen::AngleAxisd(0.4, RandomUnitVector(rng))),
                            Eigen::Vector3d(2.0, 0.0, 1.0));
  const Rigid3 world_from_cam = world_from_map.TransformPose(map_from_cam);
  const Eigen::Vector3d p_in_cam(0.1, 0.2, 3.0);
  // The direction of a ray is preserved; only the length scales.
  const Eigen::Vector3d expected =
      world_from_map * (map_from_cam * p_in_cam) - world_from_map * map_from_cam.translation;
  const Eigen::Vector3d actual = world_from_cam * p_in_cam - world_from_cam.translation;
  EXPECT_TRUE(actual.isApprox(expected / world_from_map.scale, 1e-12));
  EXPECT_TRUE(
      world_from_cam.translation.isApprox(world_from_map * map_from_cam.translation, 1e-12));
}

TEST(Sim3Test, ExpMatchesTheMatrixExponential) {
  for (const Vector7d& v : TestTangents(3)) {
    Eigen::Matrix4d generator = Eigen::Matrix4d::Zero();
    generator.topLeftCorner<3, 3>() = Hat(v.segment<3>(3)) + v(6) * Eigen::Matrix3d::Identity();
    generator.topRightCorner<3, 1>() = v.head<3>();
    const Eigen::Matrix4d expected = generator.exp();
    const Sim3 actual = Sim3::Exp(v);
    EXPECT_NEAR(actual.scale, std::exp(v(6)), 1e-14 * actual.scale);
    EXPECT_LT((actual.ToMatrix() - expected).norm(), 1e-13 * expected.norm())
        << "tangent " << v.transpose();
  }
}

TEST(Sim3Test, LogOfExpAndExpOfLogAreIdentityMaps) {
  for (const Vector7d& v : TestTangents(4)) {
    const Vector7d back = Sim3::Exp(v).Log();
    EXPECT_LT((back - v).norm(), 1e-11 * (1.0 + v.norm()))
        << "tangent " << v.transpose() << "\nback    " << back.transpose();
  }
  std::mt19937 rng(5);
  for (int i = 0; i < 200; ++i) {
    const Sim3 x = RandomSim3(rng);
    EXPECT_LT((Sim3::Exp(x.Log()).ToMatrix() - x.ToMatrix()).norm(), 1e-12 * x.ToMatrix().norm());
  }
}

// With sigma = 0 the similarity exponential is the rigid one.
TEST(Sim3Test, ExpWithZeroScaleIsRigidExp) {
  for (const Vector7d& v : TestTangents(6)) {
    Vector7d rigid_tangent = v;
    rigid_tangent(6) = 0.0;
    const Sim3 similarity = Sim3::Exp(rigid_tangent);
    const Rigid3 rigid = Rigid3::Exp(rigid_tangent.head<6>());
    EXPECT_EQ(similarity.scale, 1.0);
    EXPECT_LT((similarity.ToMatrix() - rigid.ToMatrix()).norm(), 1e-13 * (1.0 + v.norm()));
  }
}

}  // namespace
}  // namespace arucoslam
