// OptimizePoseWithMarkers: motion-only optimisation of one frame against map points and known
// (fixed) markers: keypoint and marker-corner residuals, robust LM with outlier rounds.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "arucoslam/optim/marker_bundle_adjustment.h"
#include "arucoslam/optim/pose_optimizer.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

// A fixed marker seen in the frame.
struct MarkerPoseObservation {
  Rigid3 world_from_marker;
  double size = 0.0;                            // side of the black square, metres
  std::array<Eigen::Vector2d, 4> corners_px{};  // undistorted pixels, OpenCV order
  double sigma_px = 1.0;                        // corner noise, pixels
};

struct MarkerPoseOptimizationOptions {
  // Rounds, iterations, keypoint Huber threshold and chi-square test (see pose_optimizer.h).
  // keypoints.min_inliers applies only when no marker is an inlier: one inlier marker
  // (4 corners, a full pose on its own) makes the result a success.
  PoseOptimizationOptions keypoints;
  // Huber threshold on a marker's whitened 8-vector norm (dimensionless), sqrt(15.507).
  double marker_huber_delta = 3.937892;
  // |r|^2 / sigma^2 of a marker above this makes it an outlier (chi-square, 8 dof, 95%).
  double marker_chi_square_threshold = kChiSquare8Dof95;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Nested("keypoints", keypoints);
    check.Above("marker_huber_delta", marker_huber_delta, 0.0);
    check.Above("marker_chi_square_threshold", marker_chi_square_threshold, 0.0);
    return check.ok();
  }
};

struct MarkerPoseOptimizationResult {
  bool success = false;
  Rigid3 cam_from_world;
  std::vector<bool> inliers;         // per keypoint observation
  std::vector<bool> marker_inliers;  // per marker observation
  int num_inliers = 0;
  int num_marker_inliers = 0;
  double final_rms_px = 0.0;         // keypoint inliers
  double final_marker_rms_px = 0.0;  // corners of inlier markers
};

MarkerPoseOptimizationResult OptimizePoseWithMarkers(
    const std::vector<PoseObservation>& observations,
    const std::vector<MarkerPoseObservation>& markers, const Rigid3& initial_cam_from_world,
    const PinholeIntrinsics& intrinsics, const MarkerPoseOptimizationOptions& options = {});

}  // namespace arucoslam
