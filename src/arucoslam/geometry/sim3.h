// Sim3: a similarity transform x -> scale * R * x + t, used to align a monocular map
// (arbitrary scale) to the world and for loop-closure corrections.
#pragma once

#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

using Vector7d = Eigen::Matrix<double, 7, 1>;

struct Sim3 {
  double scale = 1.0;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Sim3() = default;
  Sim3(double scale_in, const Eigen::Quaterniond& rotation_in,
       const Eigen::Vector3d& translation_in)
      : scale(scale_in), rotation(rotation_in.normalized()), translation(translation_in) {}
  explicit Sim3(const Rigid3& rigid)
      : scale(1.0), rotation(rigid.rotation), translation(rigid.translation) {}

  static Sim3 Identity() { return Sim3(); }
  Eigen::Matrix4d ToMatrix() const;

  Sim3 Inverse() const;
  Sim3 operator*(const Sim3& other) const {
    return Sim3(scale * other.scale, rotation * other.rotation,
                scale * (rotation * other.translation) + translation);
  }
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return scale * (rotation * point) + translation;
  }
  // Applies this similarity to a rigid pose `world_from_x` expressed in the source frame:
  // rotation composes, the position is transformed, the scale is not carried.
  Rigid3 TransformPose(const Rigid3& pose) const {
    return Rigid3(rotation * pose.rotation, *this * pose.translation);
  }

  // Group exponential and logarithm: tangent = [upsilon (3); omega (3); sigma = log scale].
  static Sim3 Exp(const Vector7d& tangent);
  Vector7d Log() const;
};

}  // namespace arucoslam
