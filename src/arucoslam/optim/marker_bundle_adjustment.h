// Bundle adjustment with markers: keyframe poses, map points and markers over keypoint and
// marker-corner observations; known markers fixed, unknown ones estimated (Ceres underneath).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/optim/bundle_adjustment.h"
#include "arucoslam/optim/ground_plane_error.h"
#include "arucoslam/optim/marker_corner_error.h"
#include "arucoslam/optim/position_prior_error.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

// Chi-square threshold of the 8-vector of one marker's corner residuals at 95% (8 dof).
inline constexpr double kChiSquare8Dof95 = 15.507;

struct MarkerBundleAdjustmentOptions {
  // Keypoint side: iterations, keypoint Huber threshold and chi-square test, threads,
  // tolerance (see BundleAdjustmentOptions).
  BundleAdjustmentOptions solver;
  // Huber threshold on the whitened norm of a marker's 8-vector (|r| / sigma, dimensionless).
  // sqrt(15.507): an 8-dof observation within its 95% bound is plain least squares.
  double marker_huber_delta = 3.937892;
  // A marker observation with |r|^2 / sigma^2 above this after the solve is an outlier.
  double marker_chi_square_threshold = kChiSquare8Dof95;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Nested("solver", solver);
    check.Above("marker_huber_delta", marker_huber_delta, 0.0);
    check.Above("marker_chi_square_threshold", marker_chi_square_threshold, 0.0);
    return check.ok();
  }
};

struct MarkerBundleAdjustmentProblem {
  struct Marker {
    Rigid3 world_from_marker;
    double size = 0.0;   // side of the black square, metres
    bool fixed = false;  // known marker (markers.json): held constant
  };
  struct CornerObservation {
    std::size_t pose_index = 0;                   // into keypoints.poses
    std::size_t marker_index = 0;                 // into markers
    std::array<Eigen::Vector2d, 4> corners_px{};  // undistorted pixels, OpenCV order
    double sigma_px = 1.0;                        // corner noise, pixels
  };

  // Poses, points, keypoint observations and the single camera's intrinsics.
  BundleAdjustmentProblem keypoints;
  std::vector<Marker> markers;
  std::vector<CornerObservation> marker_observations;
  // Set: the poses are a ground vehicle's camera in a z-up world with a level floor; every
  // pose an observation touches gets the GroundPlaneError prior, the plane (height and
  // mounting tilt) estimated with them, starting from the poses' MeanGroundPlane.
  std::optional<GroundPlanePriorOptions> ground_plane_prior;
  // Soft priors on camera centres (e.g. the bridge over a tracking gap); pose_index into
  // keypoints.poses.
  std::vector<PositionPrior> position_priors;

  // Everything BundleAdjustmentProblem::Check tests, plus marker indices, sizes and sigmas.
  bool Check(std::string* reason = nullptr) const;
};

struct MarkerBundleAdjustmentSummary {
  bool success = false;  // the solver ran and returned a usable solution
  int num_iterations = 0;
  int num_residual_blocks = 0;
  double initial_cost = 0.0;  // Ceres cost (half the robustified squared whitened error)
  double final_cost = 0.0;
  double initial_keypoint_rms_px = 0.0;  // unweighted RMS over keypoint observations
  double final_keypoint_rms_px = 0.0;
  double initial_marker_rms_px = 0.0;  // unweighted RMS over all marker corners
  double final_marker_rms_px = 0.0;
  double corner_sigma_px = 0.0;  // set when the caller re-weighted the corners (else 0)
  // Position priors in the solve (on poses an observation uses) and, after it, the largest
  // distance of such a camera from its prior, in the prior's sigmas.
  int num_position_priors = 0;
  double max_position_prior_sigmas = 0.0;
  double solve_seconds = 0.0;
  std::vector<bool> keypoint_outliers;  // per keypoint observation, chi-square 2 dof
  std::vector<bool> marker_outliers;    // per marker observation, chi-square 8 dof
  int num_keypoint_outliers = 0;
  int num_marker_outliers = 0;
  std::optional<GroundPlane> ground_plane;  // the estimated plane, with a ground-plane prior
  bool stopped_early = false;               // ended by solver.stop_requested
  std::string message;

  std::string BriefReport() const;
};

// Solves in place (poses, points and non-fixed markers that an observation touches). The
// gauge: fixed markers fix position, orientation and metric scale; without any, fix poses.
MarkerBundleAdjustmentSummary SolveMarkerBundleAdjustment(
    const MarkerBundleAdjustmentOptions& options, MarkerBundleAdjustmentProblem* problem);

// RMS corner error in pixels over marker observations whose corners are all in front.
double MarkerReprojectionRmsPixels(const MarkerBundleAdjustmentProblem& problem);

// The corner noise (pixels) that gives the marker corners of a solved problem the same median
// whitened residual as its keypoints (a variance-component estimate: corner and keypoint
// noise differ by detector, and a solve weighs them by the sigmas it is given), clamped to
// [min_px, max_px]. nullopt without residuals on either side.
std::optional<double> BalancedCornerSigmaPx(const MarkerBundleAdjustmentProblem& problem,
                                            double min_px, double max_px);

}  // namespace arucoslam
