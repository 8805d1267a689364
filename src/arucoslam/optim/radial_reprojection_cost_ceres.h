// Internal to optim/'s *_ceres.cc files: the reprojection cost with one more parameter, a
// radial coefficient k acting on the normalised pinhole projection (optim/radial_refinement.h).
#pragma once

#include <ceres/ceres.h>

#include <algorithm>

#include <Eigen/Core>

#include "arucoslam/optim/reprojection_error.h"
#include "arucoslam/optim/se3_manifold_ceres.h"

namespace arucoslam::ceres_internal {

// Whitened residual of the projection with the radial term: pixel' = c + f x (1 + k |x|^2)
// with x the pinhole projection's normalised coordinates; analytic Jacobians (pose tangent in
// the first six columns, as Se3LeftManifold expects).
class RadialReprojectionCost : public ceres::SizedCostFunction<2, kPoseSize, 3, 1> {
 public:
  RadialReprojectionCost(const PinholeIntrinsics& intrinsics, const Eigen::Vector2d& pixel,
                         double sigma_px)
      : error_(intrinsics, pixel), intrinsics_(intrinsics), pixel_(pixel),
        inverse_sigma_(1.0 / sigma_px) {}

  bool Evaluate(const double* const* parameters, double* residuals,
                double** jacobians) const override {
    const double k = parameters[2][0];
    Eigen::Vector2d pinhole_residual;
    PoseJacobian d_pose;
    PointJacobian d_point;
    const bool want = jacobians != nullptr;
    Eigen::Map<Eigen::Vector2d> whitened(residuals);
    if (!error_.Evaluate(PoseFromBlock(parameters[0]),
                         Eigen::Map<const Eigen::Vector3d>(parameters[1]), &pinhole_residual,
                         want ? &d_pose : nullptr, want ? &d_point : nullptr)) {
      whitened.setZero();  // behind the camera: no information
      if (want) {
        for (int b = 0; b < 3; ++b) {
          if (jacobians[b] != nullptr) {
            std::fill(jacobians[b], jacobians[b] + 2 * (b == 0 ? kPoseSize : b == 1 ? 3 : 1), 0.0);
          }
        }
      }
      return true;
    }
    const Eigen::Vector2d focal(intrinsics_.fx, intrinsics_.fy);
    const Eigen::Vector2d centre(intrinsics_.cx, intrinsics_.cy);
    const Eigen::Vector2d x = (pinhole_residual + pixel_ - centre).cwiseQuotient(focal);
    const double r2 = x.squaredNorm();
    const Eigen::Vector2d projected = centre + focal.cwiseProduct(x * (1.0 + k * r2));
    whitened = inverse_sigma_ * (projected - pixel_);
    if (!want) return true;
    // d projected / d pinhole pixel = F G F^-1 with G = (1 + k r2) I + 2 k x x^T.
    const Eigen::Matrix2d g = (1.0 + k * r2) * Eigen::Matrix2d::Identity() + 2.0 * k * x * x.transpose();
    const Eigen::Matrix2d chain = focal.asDiagonal() * g * focal.cwiseInverse().asDiagonal();
    if (jacobians[0] != nullptr) {
      WritePoseJacobian<2>(chain * d_pose, inverse_sigma_, jacobians[0]);
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> j(jacobians[1]);
      j = inverse_sigma_ * chain * d_point;
    }
    if (jacobians[2] != nullptr) {
      Eigen::Map<Eigen::Vector2d> j(jacobians[2]);
      j = inverse_sigma_ * r2 * focal.cwiseProduct(x);
    }
    return true;
  }

 private:
  ReprojectionError error_;
  PinholeIntrinsics intrinsics_;
  Eigen::Vector2d pixel_;
  double inverse_sigma_;
};

}  // namespace arucoslam::ceres_internal
