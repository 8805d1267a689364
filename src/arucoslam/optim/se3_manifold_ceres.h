// Internal to optim/'s *_ceres.cc files: a pose stored as a Ceres block [qx qy qz qw tx ty tz]
// and the left-multiplicative SE(3) manifold on it.
#pragma once

#include <ceres/ceres.h>

#include <array>

#include "arucoslam/geometry/rigid3.h"

namespace arucoslam::ceres_internal {

inline constexpr int kPoseSize = 7;
inline constexpr int kPoseTangentSize = 6;
using PoseBlock = std::array<double, kPoseSize>;

inline Rigid3 PoseFromBlock(const double* block) {
  return Rigid3(Eigen::Quaterniond(block[3], block[0], block[1], block[2]),
                Eigen::Vector3d(block[4], block[5], block[6]));
}

inline PoseBlock PoseToBlock(const Rigid3& pose) {
  const Eigen::Quaterniond q = pose.rotation.normalized();
  return {q.x(), q.y(), q.z(), q.w(), pose.translation.x(), pose.translation.y(),
          pose.translation.z()};
}

inline void PoseToBlock(const Rigid3& pose, double* block) {
  const PoseBlock values = PoseToBlock(pose);
  std::copy(values.begin(), values.end(), block);
}

// Writes a residual's Jacobian w.r.t. the pose tangent (Rows x 6), times `scale`, into a
// Rows x 7 row-major Ceres block: the first six columns, the seventh zero (see below).
template <int Rows>
void WritePoseJacobian(const Eigen::Matrix<double, Rows, kPoseTangentSize>& d, double scale,
                       double* out) {
  Eigen::Map<Eigen::Matrix<double, Rows, kPoseSize, Eigen::RowMajor>> j(out);
  j.template leftCols<kPoseTangentSize>() = scale * d;
  j.col(kPoseTangentSize).setZero();
}

// x + delta = Exp(delta) * x. The cost functions report their Jacobians directly w.r.t.
// delta in the first six ambient columns (the seventh is zero), so PlusJacobian is [I6; 0]
// and Ceres' product gives the tangent Jacobian exactly.
class Se3LeftManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseSize; }
  int TangentSize() const override { return kPoseTangentSize; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    const Vector6d tangent = Eigen::Map<const Vector6d>(delta);
    PoseToBlock(Rigid3::Exp(tangent) * PoseFromBlock(x), x_plus_delta);
    return true;
  }
  bool PlusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, kPoseSize, kPoseTangentSize, Eigen::RowMajor>> j(jacobian);
    j.setZero();
    j.topRows<kPoseTangentSize>().setIdentity();
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    Eigen::Map<Vector6d> tangent(y_minus_x);
    tangent = (PoseFromBlock(y) * PoseFromBlock(x).Inverse()).Log();
    return true;
  }
  bool MinusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, kPoseTangentSize, kPoseSize, Eigen::RowMajor>> j(jacobian);
    j.setZero();
    j.leftCols<kPoseTangentSize>().setIdentity();
    return true;
  }
};

}  // namespace arucoslam::ceres_internal
