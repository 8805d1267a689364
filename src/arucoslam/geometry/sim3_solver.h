// Sim3 solver for loop closing: estimates candidate_from_current (a similarity, or a rigid
// transform when the map is metric) from 3D-3D point matches with RANSAC, then refines it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/sim3.h"

namespace arucoslam {

// One map point matched between two keyframes, each side in its own camera frame, with the
// undistorted pixel of the keypoint that observes it and that keypoint's noise.
struct Sim3Correspondence {
  Eigen::Vector3d p_in_current = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_in_candidate = Eigen::Vector3d::Zero();
  Eigen::Vector2d pixel_in_current = Eigen::Vector2d::Zero();    // undistorted pixel
  Eigen::Vector2d pixel_in_candidate = Eigen::Vector2d::Zero();  // undistorted pixel
  double sigma_current_px = 1.0;    // keypoint noise at its pyramid level, pixels
  double sigma_candidate_px = 1.0;  // idem in the candidate keyframe
};

struct Sim3SolverOptions {
  // RANSAC: at most this many minimal (3-point) samples.
  int max_ransac_iterations = 300;
  // RANSAC stops early once a sample with this probability of being all-inlier was seen.
  double confidence = 0.99;
  // A match is an inlier when |r|^2 / sigma^2 is below this in BOTH images (chi-square,
  // 2 dof, 99%).
  double chi_square_threshold = 9.21;
  // Fewer inliers than this (after refinement) is a failure.
  int min_inliers = 20;
  // Metric map (markers): estimate a rigid transform, scale exactly 1.
  bool fix_scale = false;
  // Levenberg-Marquardt iterations on the inliers' reprojection errors (0: no refinement).
  int refine_iterations = 10;
  // Huber threshold of the refinement on the whitened residual (sqrt of the chi-square).
  double huber_delta = 3.0348;  // sqrt(9.21)
  // Reprojection errors fix the scale only through the translation between the cameras: when
  // it is below this fraction of the median depth of the inliers (candidate side) the
  // refinement keeps the scale of the 3D fit (at zero baseline it could drift to zero).
  double min_scale_baseline_ratio = 0.05;
  // A scale outside [min_scale, max_scale] is no loop (monocular drift is never that large).
  double min_scale = 0.1;
  double max_scale = 10.0;
  std::uint32_t seed = 1;       // random sampling, deterministic for a seed

  bool Check(std::string* why = nullptr) const;
};

struct Sim3SolverResult {
  bool success = false;
  Sim3 candidate_from_current;
  std::vector<bool> inliers;  // per correspondence, after refinement
  int num_inliers = 0;
  int num_ransac_iterations = 0;
  double inlier_rms_px = 0.0;  // RMS pixel error of the inliers over both images
  std::string message;         // reason of a failure
};

// Pixels are undistorted: only the pinhole part (fx fy cx cy) of each camera is used.
Sim3SolverResult SolveSim3(const CameraModel& current_camera, const CameraModel& candidate_camera,
                           const std::vector<Sim3Correspondence>& correspondences,
                           const Sim3SolverOptions& options = {});

// Squared whitened reprojection errors of one match under candidate_from_current:
// first in the candidate image, second in the current image (infinity behind a camera).
Eigen::Vector2d Sim3ChiSquares(const CameraModel& current_camera,
                               const CameraModel& candidate_camera,
                               const Sim3Correspondence& correspondence,
                               const Sim3& candidate_from_current);

}  // namespace arucoslam
