// Rigid3: a rotation and a translation (SE(3)), named for what it does: `b_from_a * p_in_a`
// gives p_in_b. Tangent vectors are [translation part (3); rotation part (3)].
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace arucoslam {

using Vector6d = Eigen::Matrix<double, 6, 1>;

struct Rigid3 {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3() = default;
  Rigid3(const Eigen::Quaterniond& rotation_in, const Eigen::Vector3d& translation_in)
      : rotation(rotation_in.normalized()), translation(translation_in) {}
  Rigid3(const Eigen::Matrix3d& rotation_matrix, const Eigen::Vector3d& translation_in)
      : rotation(Eigen::Quaterniond(rotation_matrix).normalized()),
        translation(translation_in) {}

  static Rigid3 Identity() { return Rigid3(); }
  // From a 4x4 (or top 3x4) homogeneous matrix; the rotation block is re-orthonormalised.
  static Rigid3 FromMatrix(const Eigen::Matrix4d& matrix);
  Eigen::Matrix4d ToMatrix() const;
  Eigen::Matrix3d RotationMatrix() const { return rotation.toRotationMatrix(); }

  Rigid3 Inverse() const;
  Rigid3 operator*(const Rigid3& other) const {
    return Rigid3(rotation * other.rotation, rotation * other.translation + translation);
  }
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation * point + translation;
  }

  // Group exponential and logarithm: tangent = [upsilon; omega].
  static Rigid3 Exp(const Vector6d& tangent);
  Vector6d Log() const;

  // Adjoint matrix (6x6) acting on [upsilon; omega].
  Eigen::Matrix<double, 6, 6> Adjoint() const;
};

// Geodesic interpolation: t = 0 gives `a`, t = 1 gives `b` (rotation by slerp,
// translation linear, as trajectory interpolation expects).
Rigid3 Interpolate(const Rigid3& a, const Rigid3& b, double t);

// Rotation angle of a quaternion in [0, pi] radians.
double RotationAngle(const Eigen::Quaterniond& rotation);

// SO(3) helpers shared by Rigid3 and Sim3.
Eigen::Matrix3d Hat(const Eigen::Vector3d& v);
Eigen::Quaterniond ExpSO3(const Eigen::Vector3d& omega);
Eigen::Vector3d LogSO3(const Eigen::Quaterniond& rotation);

}  // namespace arucoslam
