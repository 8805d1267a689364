#include "arucoslam/optim/marker_bundle_adjustment.h"

#include <cmath>
#include <sstream>

#include "arucoslam/markers/marker_pose.h"

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
  return true;
}

double MarkerReprojectionRmsPixels(const MarkerBundleAdjustmentProblem& problem) {
  double sum = 0.0;
  int count = 0;
  for (const auto& observation : problem.marker_observations) {
    const auto& marker = problem.markers[observation.marker_index];
    Vector8d residual;
    const MarkerCornerError error(problem.keypoints.intrinsics, SquareCorners(marker.size),
                                  observation.corners_px);
    if (error.Evaluate(problem.keypoints.poses[observation.pose_index].cam_from_world,
                       marker.world_from_marker, &residual)) {
      sum += residual.squaredNorm();
      count += 4;
    }
  }
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

std::string MarkerBundleAdjustmentSummary::BriefReport() const {
  std::ostringstream out;
  out << (success ? "ok" : "failed") << ", " << num_iterations << " iterations, "
      << num_residual_blocks << " residual blocks, keypoint RMS " << initial_keypoint_rms_px
      << " -> " << final_keypoint_rms_px << " px, marker RMS " << initial_marker_rms_px << " -> "
      << final_marker_rms_px << " px, outliers " << num_keypoint_outliers << " keypoint / "
      << num_marker_outliers << " marker, " << solve_seconds << " s (" << message << ")";
  return out.str();
}

}  // namespace arucoslam
