#include "arucoslam/optim/bundle_adjustment.h"

#include <fmt/format.h>

#include <cmath>

#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool BundleAdjustmentOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("max_iterations", max_iterations, 1);
  check.Above("huber_delta_px", huber_delta_px, 0.0);
  check.Above("chi_square_threshold", chi_square_threshold, 0.0);
  check.AtLeast("num_threads", num_threads, 1);
  check.Above("function_tolerance", function_tolerance, 0.0);
  check.AtLeast("min_iterations_before_stop", min_iterations_before_stop, 0);
  return check.ok();
}

bool BundleAdjustmentProblem::Check(std::string* reason) const {
  auto fail = [reason](std::string text) {
    if (reason != nullptr) *reason = std::move(text);
    return false;
  };
  if (!intrinsics.Check()) return fail("intrinsics: focal lengths must be positive");
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const Observation& observation = observations[i];
    if (observation.pose_index >= poses.size()) {
      return fail(
          fmt::format("observation {}: pose index {} out of range", i, observation.pose_index));
    }
    if (observation.point_index >= points.size()) {
      return fail(
          fmt::format("observation {}: point index {} out of range", i, observation.point_index));
    }
    if (!(observation.sigma_px > 0.0) || !observation.pixel.allFinite()) {
      return fail(fmt::format("observation {}: sigma must be positive, pixel finite", i));
    }
  }
  return true;
}

std::string BundleAdjustmentSummary::BriefReport() const {
  return fmt::format(
      "bundle adjustment: {} residuals, {} iterations, cost {:.4g} -> {:.4g}, rms {:.3f} -> "
      "{:.3f} px, {} outliers, {:.1f} ms ({})",
      num_residual_blocks, num_iterations, initial_cost, final_cost, initial_rms_px, final_rms_px,
      num_outliers, 1e3 * solve_seconds, message);
}

double ReprojectionRmsPixels(const BundleAdjustmentProblem& problem) {
  double sum = 0.0;
  int count = 0;
  VisitReprojectionResiduals(
      problem, [&](const BundleAdjustmentProblem::Observation&, const Eigen::Vector2d& residual) {
        sum += residual.squaredNorm();
        ++count;
      });
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

std::vector<bool> FlagReprojectionOutliers(const BundleAdjustmentProblem& problem,
                                           double chi_square_threshold, int* num_outliers) {
  std::vector<bool> outliers(problem.observations.size(), false);
  *num_outliers = 0;
  for (std::size_t i = 0; i < problem.observations.size(); ++i) {
    const auto& observation = problem.observations[i];
    Eigen::Vector2d residual;
    const bool in_front =
        ReprojectionError(problem.intrinsics, observation.pixel)
            .Evaluate(problem.poses[observation.pose_index].cam_from_world,
                      problem.points[observation.point_index].p_in_world, &residual);
    const double chi2 = residual.squaredNorm() / (observation.sigma_px * observation.sigma_px);
    if (!in_front || chi2 > chi_square_threshold) {
      outliers[i] = true;
      ++*num_outliers;
    }
  }
  return outliers;
}

void VisitReprojectionResiduals(
    const BundleAdjustmentProblem& problem,
    const std::function<void(const BundleAdjustmentProblem::Observation&,
                             const Eigen::Vector2d&)>& visit) {
  for (const auto& observation : problem.observations) {
    Eigen::Vector2d residual;
    if (ReprojectionError(problem.intrinsics, observation.pixel)
            .Evaluate(problem.poses[observation.pose_index].cam_from_world,
                      problem.points[observation.point_index].p_in_world, &residual)) {
      visit(observation, residual);
    }
  }
}

}  // namespace arucoslam
