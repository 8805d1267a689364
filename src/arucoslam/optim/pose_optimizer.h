// OptimizePose: motion-only optimisation of one camera pose against known 3D points (used by
// tracking), robust (Huber) Gauss-Newton/Levenberg-Marquardt with chi-square outlier rounds.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/optim/reprojection_error.h"

namespace arucoslam {

// One 2D-3D correspondence: a map point and the undistorted pixel of its keypoint.
struct PoseObservation {
  Eigen::Vector3d p_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // undistorted pixel coordinates
  double sigma_px = 1.0;  // keypoint noise in pixels (1.2^octave for an ORB pyramid)
};

struct PoseOptimizationOptions {
  // Outlier-classification rounds; after each, every observation is re-classified.
  int num_rounds = 4;
  // Levenberg-Marquardt iterations inside one round.
  int iterations_per_round = 10;
  // Rounds (from the first) that use the Huber loss; the rest are plain least squares on
  // the inliers.
  int num_robust_rounds = 3;
  // Huber threshold on the whitened residual |r| / sigma (dimensionless; sqrt(5.991)).
  double huber_delta = 2.447688;
  // |r|^2 / sigma^2 above this makes an observation an outlier (chi-square, 2 dof, 95%).
  double chi_square_threshold = kChiSquare2Dof95;
  // Fewer inliers than this after a round: stop, the result is reported as failed.
  int min_inliers = 10;

  bool Check(std::string* why = nullptr) const;
};

struct PoseOptimizationResult {
  bool success = false;  // at least min_inliers inliers at the end
  Rigid3 cam_from_world;
  std::vector<bool> inliers;  // one flag per observation
  int num_inliers = 0;
  double initial_rms_px = 0.0;  // over all observations in front of the initial pose
  double final_rms_px = 0.0;    // over the final inliers
};

PoseOptimizationResult OptimizePose(const std::vector<PoseObservation>& observations,
                                    const Rigid3& initial_cam_from_world,
                                    const PinholeIntrinsics& intrinsics,
                                    const PoseOptimizationOptions& options = {});

}  // namespace arucoslam
