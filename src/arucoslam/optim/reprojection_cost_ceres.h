// Internal to optim/'s *_ceres.cc files: ReprojectionError as a Ceres cost over a pose block
// [qx qy qz qw tx ty tz] on the left SE(3) manifold and a 3D point block, whitened by sigma.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "arucoslam/optim/reprojection_error.h"
#include "arucoslam/optim/se3_manifold_ceres.h"

namespace arucoslam::ceres_internal {

// Residual r / sigma (r in pixels, sigma the keypoint's pixel noise) with the analytic
// Jacobians of ReprojectionError. A point behind the camera gives a zero residual and zero
// Jacobians: no information (the callers flag it as an outlier after the solve).
class ReprojectionCost : public ceres::SizedCostFunction<2, kPoseSize, 3> {
 public:
  ReprojectionCost(const PinholeIntrinsics& intrinsics, const Eigen::Vector2d& pixel,
                   double sigma_px)
      : error_(intrinsics, pixel), inverse_sigma_(1.0 / sigma_px) {}

  bool Evaluate(const double* const* parameters, double* residuals,
                double** jacobians) const override {
    Eigen::Vector2d residual = Eigen::Vector2d::Zero();
    PoseJacobian d_pose = PoseJacobian::Zero();
    PointJacobian d_point = PointJacobian::Zero();
    const bool want = jacobians != nullptr;
    if (!error_.Evaluate(PoseFromBlock(parameters[0]),
                         Eigen::Map<const Eigen::Vector3d>(parameters[1]), &residual,
                         want ? &d_pose : nullptr, want ? &d_point : nullptr)) {
      residual.setZero();
      d_pose.setZero();
      d_point.setZero();
    }
    Eigen::Map<Eigen::Vector2d> whitened(residuals);
    whitened = inverse_sigma_ * residual;
    if (want && jacobians[0] != nullptr) {
      WritePoseJacobian<2>(d_pose, inverse_sigma_, jacobians[0]);
    }
    if (want && jacobians[1] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> j(jacobians[1]);
      j = inverse_sigma_ * d_point;
    }
    return true;
  }

 private:
  ReprojectionError error_;
  double inverse_sigma_;
};

// The reprojection costs of one solve in a single allocation, for a ceres::Problem built with
// cost_function_ownership = DO_NOT_TAKE_OWNERSHIP: no allocation and no Ceres ownership
// bookkeeping per residual block. Must outlive the problem.
class ReprojectionCosts {
 public:
  explicit ReprojectionCosts(std::size_t capacity) : costs_(capacity) {}
  // The next cost; at most `capacity` of them.
  ReprojectionCost* Add(const PinholeIntrinsics& intrinsics, const Eigen::Vector2d& pixel,
                        double sigma_px) {
    std::optional<ReprojectionCost>& slot = costs_.at(size_++);
    slot.emplace(intrinsics, pixel, sigma_px);
    return &*slot;
  }

 private:
  std::vector<std::optional<ReprojectionCost>> costs_;  // never reallocated: Ceres keeps pointers
  std::size_t size_ = 0;
};

}  // namespace arucoslam::ceres_internal
