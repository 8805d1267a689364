#include "arucoslam/eval/evaluation.h"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "arucoslam/util/error.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool EvaluationOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Nested("association", association);
  check.Nested("alignment", alignment);
  check.Nested("per_axis", per_axis);
  check.Nested("completeness", completeness);
  if (scale_drift) check.Nested("scale_drift", *scale_drift);
  for (std::size_t i = 0; i < relative.size(); ++i) {
    check.Nested(fmt::format("relative[{}]", i), relative[i]);
  }
  return check.ok();
}

namespace {

AssociatedTrajectories Associate(const Trajectory& gt, const Trajectory& est,
                                 const std::string& est_source, const EvaluationOptions& options) {
  if (options.associate_by_index) {
    if (gt.size() != est.size()) {
      throw InputError(est_source, fmt::format("{} poses, ground truth has {} (pairing by "
                                               "index needs the same count)",
                                               est.size(), gt.size()));
    }
    return AssociateByIndex(gt, est);
  }
  AssociatedTrajectories pairs = AssociateByTime(gt, est, options.association);
  if (pairs.size() == 0) {
    throw InputError(est_source, fmt::format("no pose within {} s of a ground-truth pose (estimate "
                                             "{:.3f}..{:.3f} s, ground truth {:.3f}..{:.3f} s)",
                                             options.association.max_time_difference,
                                             est.timestamps.front(), est.timestamps.back(),
                                             gt.timestamps.front(), gt.timestamps.back()));
  }
  return pairs;
}

}  // namespace

TrajectoryEvaluation EvaluateTrajectory(const Trajectory& gt, const Trajectory& est,
                                        const std::string& label, const std::string& est_source,
                                        const EvaluationOptions& options) {
  if (!options.Check()) throw std::invalid_argument("EvaluationOptions: invalid");
  if (gt.empty() || est.empty()) throw InputError(est_source, "empty trajectory");
  TrajectoryEvaluation result;
  result.label = label;
  result.num_gt_poses = gt.size();
  result.num_est_poses = est.size();
  result.pairs = Associate(gt, est, est_source, options);
  if (result.pairs.size() < 3) {
    throw InputError(est_source, fmt::format("only {} pose(s) associated with the ground "
                                             "truth; at least 3 are needed",
                                             result.pairs.size()));
  }
  const std::optional<AlignmentResult> alignment =
      ComputeAlignment(result.pairs, options.alignment);
  AlignmentOptions sim3_options = options.alignment;
  sim3_options.mode = AlignmentMode::kSim3;
  const std::optional<AlignmentResult> sim3 = ComputeAlignment(result.pairs, sim3_options);
  if (!alignment || !sim3) {
    throw InputError(est_source,
                     "cannot align: fewer than 3 pairs in the alignment "
                     "selection or all positions coincide");
  }
  result.alignment = *alignment;
  result.sim3_scale = sim3->gt_from_est.scale;
  result.scale_error = std::abs(result.sim3_scale - 1.0);
  result.aligned_est = ApplyAlignment(result.alignment.gt_from_est, result.pairs.est);

  const Trajectory& gt_pairs = result.pairs.gt;
  result.ape_translation_errors =
      AbsolutePoseErrors(gt_pairs, result.aligned_est, PoseRelation::kTranslation);
  result.ape_translation = ComputeErrorStatistics(result.ape_translation_errors);
  result.ape_rotation_deg = ComputeErrorStatistics(
      AbsolutePoseErrors(gt_pairs, result.aligned_est, PoseRelation::kRotationAngleDeg));
  for (const RelativeErrorOptions& relative : options.relative) {
    const IndexPairs index_pairs = RelativeIndexPairs(result.aligned_est, relative);
    RelativeErrorResult r;
    r.options = relative;
    r.translation = ComputeErrorStatistics(
        RelativePoseErrors(gt_pairs, result.aligned_est, index_pairs, PoseRelation::kTranslation));
    r.rotation_deg = ComputeErrorStatistics(RelativePoseErrors(
        gt_pairs, result.aligned_est, index_pairs, PoseRelation::kRotationAngleDeg));
    result.relative.push_back(r);
  }
  result.per_axis = ComputePerAxisError(gt_pairs, result.aligned_est, options.per_axis);
  result.completeness = ComputeCompleteness(gt, est, options.completeness);
  if (options.scale_drift) {
    result.scale_drift = ComputeScaleDrift(result.pairs, *options.scale_drift);
  }
  return result;
}

}  // namespace arucoslam
