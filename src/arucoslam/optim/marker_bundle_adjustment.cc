#include "arucoslam/optim/marker_bundle_adjustment.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "arucoslam/markers/marker_pose.h"
#include "arucoslam/optim/reprojection_error.h"
#include "arucoslam/util/median.h"

namespace arucoslam {

bool MarkerBundleAdjustmentProblem::Check(std::string* reason) const {
  auto fail = [&](const std::string& why) {
    if (reason != nullptr) *reason = why;
    return false;
  };
  if (!keypoints.Check(reason)) return false;
  for (std::size_t i = 0; i < markers.size(); ++i) {
    if (!(markers[i].size > 0.0)) return fail("marker " + std::to_string(i) + ": size <= 0");
  }
  for (std::size_t i = 0; i < marker_observations.size(); ++i) {
    const CornerObservation& observation = marker_observations[i];
    if (observation.pose_index >= keypoints.poses.size() ||
        observation.marker_index >= markers.size()) {
      return fail("marker observation " + std::to_string(i) + ": index out of range");
    }
    if (!(observation.sigma_px > 0.0)) {
      return fail("marker observation " + std::to_string(i) + ": sigma <= 0");
    }
  }
  for (std::size_t i = 0; i < position_priors.size(); ++i) {
    if (position_priors[i].pose_index >= keypoints.poses.size()) {
      return fail("position prior " + std::to_string(i) + ": index out of range");
    }
    if (!(position_priors[i].sigma_m > 0.0)) {
      return fail("position prior " + std::to_string(i) + ": sigma <= 0");
    }
  }
  if (ground_plane_prior && !ground_plane_prior->Check()) {
    return fail("ground-plane prior: sigmas <= 0");
  }
  return true;
}

namespace {

// The corner residuals (pixels) of every marker observation whose corners are all in front.
std::vector<Vector8d> MarkerResiduals(const MarkerBundleAdjustmentProblem& problem) {
  std::vector<Vector8d> residuals;
  for (const auto& observation : problem.marker_observations) {
    const auto& marker = problem.markers[observation.marker_index];
    Vector8d residual;
    const MarkerCornerError error(problem.keypoints.intrinsics, SquareCorners(marker.size),
                                  observation.corners_px);
    if (error.Evaluate(problem.keypoints.poses[observation.pose_index].cam_from_world,
                       marker.world_from_marker, &residual)) {
      residuals.push_back(residual);
    }
  }
  return residuals;
}

}  // namespace

double MarkerReprojectionRmsPixels(const MarkerBundleAdjustmentProblem& problem) {
  double sum = 0.0;
  int count = 0;
  for (const Vector8d& residual : MarkerResiduals(problem)) {
    sum += residual.squaredNorm();
    count += 4;
  }
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

std::optional<double> BalancedCornerSigmaPx(const MarkerBundleAdjustmentProblem& problem,
                                            double min_px, double max_px) {
  std::vector<double> keypoints;  // |r| / sigma per keypoint observation
  VisitReprojectionResiduals(problem.keypoints,
                             [&](const BundleAdjustmentProblem::Observation& observation,
                                 const Eigen::Vector2d& residual) {
                               keypoints.push_back(residual.norm() / observation.sigma_px);
                             });
  std::vector<double> corners;  // |r| per marker corner, pixels
  for (const Vector8d& residual : MarkerResiduals(problem)) {
    for (int c = 0; c < 4; ++c) corners.push_back(residual.segment<2>(2 * c).norm());
  }
  if (keypoints.empty() || corners.empty()) return std::nullopt;
  // Corner residuals are in pixels: divided by the keypoints' whitened median, the sigma
  // that gives both the same median.
  const double keypoint_median = Median(std::move(keypoints));
  if (!(keypoint_median > 0.0)) return std::nullopt;
  return std::clamp(Median(std::move(corners)) / keypoint_median, min_px, max_px);
}

std::string MarkerBundleAdjustmentSummary::BriefReport() const {
  std::ostringstream out;
  out << (success ? "ok" : "failed") << ", " << num_iterations << " iterations, "
      << num_residual_blocks << " residual blocks, keypoint RMS " << initial_keypoint_rms_px
      << " -> " << final_keypoint_rms_px << " px, marker RMS " << initial_marker_rms_px << " -> "
      << final_marker_rms_px << " px, outliers " << num_keypoint_outliers << " keypoint / "
      << num_marker_outliers << " marker, ";
  if (corner_sigma_px > 0.0) out << "corners weighted at " << corner_sigma_px << " px, ";
  if (num_position_priors > 0) {
    out << num_position_priors << " position priors (at most " << max_position_prior_sigmas
        << " sigma off), ";
  }
  if (ground_plane) {
    const double tilt_deg =
        std::acos(std::clamp(-ground_plane->up_in_camera.y(), -1.0, 1.0)) * 180.0 / M_PI;
    out << "ground plane: camera height " << ground_plane->height_m << " m, tilted " << tilt_deg
        << " deg from level, ";
  }
  out << solve_seconds << " s (" << message << ")";
  return out.str();
}

}  // namespace arucoslam
