#include "arucoslam/geometry/rigid3.h"

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

// Rotation angles that stress the small-angle and near-pi branches, plus ordinary ones.
std::vector<double> TestAngles() {
  return {0.0, 1e-12, 1e-9, 3e-8,       1e-7,       1e-5,       1e-3, 0.3,
          1.0, 2.0,   3.0,  kPi - 1e-3, kPi - 1e-6, kPi - 1e-9, kPi};
}

// Random tangent vectors [upsilon; omega] with |omega| taken from TestAngles().
std::vector<Vector6d> TestTangents(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-5.0, 5.0);
  std::vector<Vector6d> tangents;
  for (const double angle : TestAngles()) {
    for (int i = 0; i < 4; ++i) {
      Vector6d v;
      v.head<3>() = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
      v.tail<3>() = angle * RandomUnitVector(rng);
      tangents.push_back(v);
    }
  }
  return tangents;
}

Rigid3 RandomRigid(std::mt19937& rng) {
  std::uniform_real_distribution<double> uniform(-10.0, 10.0);
  std::uniform_real_distribution<double> angle(0.0, kPi);
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(angle(rng), RandomUnitVector(rng))),
                Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)));
}

// Distance between two poses: rotation angle (rad) + translation difference (m).
double PoseError(const Rigid3& a, const Rigid3& b) {
  return RotationAngle(a.rotation.conjugate() * b.rotation) +
         (a.translation - b.translation).norm();
}

// Same rotation up to the sign of the angle-axis vector, which is ambiguous at exactly pi.
bool SameTangent(const Vector6d& a, const Vector6d& b, double tolerance) {
  if ((a - b).norm() < tolerance * (1.0 + a.norm())) return true;
  return std::abs(a.tail<3>().norm() - kPi) < 1e-6 &&
         (Rigid3::Exp(a).ToMatrix() - Rigid3::Exp(b).ToMatrix()).norm() < tolerance;
}

TEST(Rigid3Test, ComposeAndInverseAgreeWithMatrices) {
  std::mt19937 rng(1);
  for (int i = 0; i < 100; ++i) {
    const Rigid3 b_from_a = RandomRigid(rng);
    const Rigid3 c_from_b = RandomRigid(rng);
    const Eigen::Vector3d p_in_a(1.5, -2.0, 0.25);
    const Rigid3 c_from_a = c_from_b * b_from_a;
    EXPECT_TRUE((c_from_a * p_in_a).isApprox(c_from_b * (b_from_a * p_in_a), 1e-12));
    EXPECT_TRUE(c_from_a.ToMatrix().isApprox(c_from_b.ToMatrix() * b_from_a.ToMatrix(), 1e-12));
    EXPECT_TRUE(b_from_a.Inverse().ToMatrix().isApprox(b_from_a.ToMatrix().inverse(), 1e-12));
    EXPECT_LT(PoseError(b_from_a * b_from_a.Inverse(), Rigid3::Identity()), 1e-12);
    EXPECT_LT(PoseError(Rigid3::FromMatrix(b_from_a.ToMatrix()), b_from_a), 1e-12);
  }
}

TEST(Rigid3Test, FromMatrixReturnsTheNearestRotation) {
  const Rigid3 truth(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(1.0, 2.0, 3.0));
  Eigen::Matrix4d noisy = truth.ToMatrix();
  noisy.topLeftCorner<3, 3>() += 1e-4 * Eigen::Matrix3d::Ones();  // no longer orthonormal
  const Rigid3 recovered = Rigid3::FromMatrix(noisy);
  const Eigen::Matrix3d r = recovered.RotationMatrix();
  EXPECT_TRUE((r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  EXPECT_LT(RotationAngle(recovered.rotation.conjugate() * truth.rotation), 3e-4);
  EXPECT_TRUE(recovered.translation.isApprox(truth.translation, 1e-15));
}

TEST(Rigid3Test, ExpMatchesTheMatrixExponential) {
  for (const Vector6d& v : TestTangents(2)) {
    Eigen::Matrix4d generator = Eigen::Matrix4d::Zero();
    generator.topLeftCorner<3, 3>() = Hat(v.tail<3>());
    generator.topRightCorner<3, 1>() = v.head<3>();
    const Eigen::Matrix4d expected = generator.exp();
    EXPECT_LT((Rigid3::Exp(v).ToMatrix() - expected).norm(), 1e-13 * (1.0 + v.norm()))
        << "tangent " << v.transpose();
  }
}

TEST(Rigid3Test, ExpOfLogIsIdentityMap) {
  std::mt19937 rng(3);
  for (const double angle : TestAngles()) {
    for (int i = 0; i < 10; ++i) {
      Rigid3 pose = RandomRigid(rng);
      pose.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(angle, RandomUnitVector(rng)));
      EXPECT_LT(PoseError(Rigid3::Exp(pose.Log()), pose), 1e-12) << "angle " << angle;
    }
  }
}

TEST(Rigid3Test, LogOfExpIsIdentityMap) {
  for (const Vector6d& v : TestTangents(4)) {
    const Vector6d back = Rigid3::Exp(v).Log();
    EXPECT_TRUE(SameTangent(back, v, 1e-12))
        << "tangent " << v.transpose() << "\nback    " << back.transpose();
  }
}

TEST(Rigid3Test, SO3LogIsInverseOfExpAndAngleInRange) {
  std::mt19937 rng(5);
  for (const double angle : TestAngles()) {
    if (angle >= kPi) continue;  // the axis sign is ambiguous at pi
    const Eigen::Vector3d omega = angle * RandomUnitVector(rng);
    EXPECT_LT((LogSO3(ExpSO3(omega)) - omega).norm(), 1e-12 * (1.0 + angle)) << angle;
    EXPECT_NEAR(RotationAngle(ExpSO3(omega)), angle, 1e-12);
    // A quaternion and its negative are the same rotation.
    Eigen::Quaterniond negated = ExpSO3(omega);
    negated.coeffs() = -negated.coeffs();
    EXPECT_LT((LogSO3(negated) - omega).norm(), 1e-12 * (1.0 + angle)) << angle;
  }
}

// T * Exp(v) * T^-1 == Exp(Adj(T) v).
TEST(Rigid3Test, AdjointTransportsTangentVectors) {
  std::mt19937 rng(6);
  for (const Vector6d& v : TestTangents(7)) {
    if (v.tail<3>().norm() > 3.0) continue;  // Adj(T) v keeps |omega|; stay off the pi cut
    const Rigid3 t = RandomRigid(rng);
    const Rigid3 lhs = t * Rigid3::Exp(v) * t.Inverse();
    const Rigid3 rhs = Rigid3::Exp(t.Adjoint() * v);
    EXPECT_LT((lhs.ToMatrix() - rhs.ToMatrix()).norm(), 1e-11 * (1.0 + v.norm()))
        << "tangent " << v.transpose();
  }
}

TEST(Rigid3Test, InterpolateIsSlerpAndLinear) {
  std::mt19937 rng(8);
  for (int i = 0; i < 50; ++i) {
    const Rigid3 a = RandomRigid(rng);
    const Rigid3 b = RandomRigid(rng);
    EXPECT_LT(PoseError(Interpolate(a, b, 0.0), a), 1e-12);
    EXPECT_LT(PoseError(Interpolate(a, b, 1.0), b), 1e-12);
    for (const double t : {0.25, 0.5, 0.9}) {
      const Rigid3 c = Interpolate(a, b, t);
      EXPECT_TRUE(c.translation.isApprox((1 - t) * a.translation + t * b.translation, 1e-12));
      // On the shortest rotation geodesic: a * exp(t * log(a^-1 b)).
      const Eigen::Quaterniond expected =
          a.rotation * ExpSO3(t * LogSO3(a.rotation.conjugate() * b.rotation));
      EXPECT_LT(RotationAngle(c.rotation.conjugate() * expected), 1e-9);
      const double total = RotationAngle(a.rotation.conjugate() * b.rotation);
      EXPECT_NEAR(RotationAngle(a.rotation.conjugate() * c.rotation), t * total, 1e-9);
    }
  }
}

TEST(Rigid3Test, HatIsTheCrossProduct) {
  const Eigen::Vector3d a(0.3, -1.2, 2.5), b(-4.0, 0.5, 1.0);
  EXPECT_TRUE((Hat(a) * b).isApprox(a.cross(b), 1e-15));
}

}  // namespace
}  // namespace arucoslam
