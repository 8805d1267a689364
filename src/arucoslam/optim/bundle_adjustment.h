// Bundle adjustment of camera poses and 3D points over keypoint observations, as a plain
// problem description (no solver types here); SolveBundleAdjustment runs Ceres underneath.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/optim/reprojection_error.h"

namespace arucoslam {

struct BundleAdjustmentOptions {
  // Maximum solver iterations (Levenberg-Marquardt steps).
  int max_iterations = 20;
  // Huber threshold on the reprojection residual, in pixels at sigma 1 (the residual is
  // whitened by the observation's sigma first). sqrt(5.991) as ORB-SLAM's local BA.
  double huber_delta_px = 2.447688;
  // After solving, observations with |r|^2/sigma^2 above this (or behind the camera) are
  // reported as outliers (chi-square, 2 dof, 95%).
  double chi_square_threshold = kChiSquare2Dof95;
  // Solver threads (Jacobian evaluation and linear solver).
  int num_threads = 1;
  // Relative decrease of the cost below which the solver stops.
  double function_tolerance = 1e-6;
  // Asked after each solver iteration from iteration min_iterations_before_stop on: true ends
  // the solve there, with the best iterate so far (a usable solution; stopped_early in the
  // summary). Unset: never asked. Local mapping yields with it to a keyframe that waits.
  std::function<bool()> stop_requested;
  int min_iterations_before_stop = 1;

  bool Check(std::string* why = nullptr) const;
};

// The problem; the solver changes poses and points in place (all but the fixed ones).
struct BundleAdjustmentProblem {
  struct Pose {
    Rigid3 cam_from_world;
    bool fixed = false;  // held constant (e.g. keyframes at the border of a local window)
  };
  struct Point {
    Eigen::Vector3d p_in_world = Eigen::Vector3d::Zero();
    bool fixed = false;
  };
  struct Observation {
    std::size_t pose_index = 0;
    std::size_t point_index = 0;
    Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // undistorted pixel
    double sigma_px = 1.0;                            // keypoint noise, pixels
  };

  PinholeIntrinsics intrinsics;  // one camera for every pose
  std::vector<Pose> poses;
  std::vector<Point> points;
  std::vector<Observation> observations;

  // Indices valid, sigmas positive, intrinsics valid; else false and a reason.
  bool Check(std::string* reason = nullptr) const;
};

struct BundleAdjustmentSummary {
  bool success = false;  // the solver ran and returned a usable solution
  int num_iterations = 0;
  int num_residual_blocks = 0;
  double initial_cost = 0.0;  // Ceres cost (half the robustified squared whitened error)
  double final_cost = 0.0;
  double initial_rms_px = 0.0;  // unweighted reprojection RMS over all observations
  double final_rms_px = 0.0;
  double solve_seconds = 0.0;
  // Per observation: true when it is an outlier after the solve (chi-square test).
  std::vector<bool> outliers;
  int num_outliers = 0;
  bool stopped_early = false;  // ended by stop_requested before convergence or max_iterations
  std::string message;  // the solver's termination message or the reason of a failure

  std::string BriefReport() const;
};

// Solves in place. Poses that no observation touches are left unchanged. When no pose is
// fixed the gauge is free: fix at least one pose (and for monocular two, or accept scale drift).
BundleAdjustmentSummary SolveBundleAdjustment(const BundleAdjustmentOptions& options,
                                              BundleAdjustmentProblem* problem);

// Reprojection RMS in pixels over all observations in front of their camera.
double ReprojectionRmsPixels(const BundleAdjustmentProblem& problem);
// Per observation: true when it is behind its camera or its squared residual over sigma^2
// exceeds `chi_square_threshold` (the outlier test after a solve); `num_outliers` counts them.
std::vector<bool> FlagReprojectionOutliers(const BundleAdjustmentProblem& problem,
                                           double chi_square_threshold, int* num_outliers);
// Calls `visit(observation, residual_px)` for each observation in front of its camera.
void VisitReprojectionResiduals(
    const BundleAdjustmentProblem& problem,
    const std::function<void(const BundleAdjustmentProblem::Observation&,
                             const Eigen::Vector2d&)>& visit);

}  // namespace arucoslam
