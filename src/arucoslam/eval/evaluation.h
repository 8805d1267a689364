// EvaluateTrajectory: the whole comparison of one estimate with ground truth (association,
// alignment, APE, RPE, per-axis error, scale, completeness), as `arucoslam eval` reports it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "arucoslam/eval/alignment.h"
#include "arucoslam/eval/association.h"
#include "arucoslam/eval/completeness.h"
#include "arucoslam/eval/map_accuracy.h"
#include "arucoslam/eval/per_axis_error.h"
#include "arucoslam/eval/pose_error.h"
#include "arucoslam/eval/scale_drift.h"
#include "arucoslam/eval/statistics.h"

namespace arucoslam {

struct EvaluationOptions {
  AssociationOptions association;  // max time difference 0.01 s (evo's default)
  AlignmentOptions alignment;      // none by default: a world-anchored system's own frame
  // RPE deltas to report; default: 1 frame (consecutive pairs).
  std::vector<RelativeErrorOptions> relative = {RelativeErrorOptions{}};
  PerAxisErrorOptions per_axis;      // no timestamps by default
  CompletenessOptions completeness;  // gap threshold automatic
  // Pair poses by index instead of time (both files without time, e.g. KITTI).
  bool associate_by_index = false;
  // Set: the Sim(3) scale over consecutive windows of this many seconds (scale_drift.h).
  std::optional<ScaleDriftOptions> scale_drift;

  bool Check(std::string* why = nullptr) const;
};

struct RelativeErrorResult {
  RelativeErrorOptions options;
  ErrorStatistics translation;   // m
  ErrorStatistics rotation_deg;  // degrees
};

struct TrajectoryEvaluation {
  std::string label;
  std::size_t num_gt_poses = 0;
  std::size_t num_est_poses = 0;
  AssociatedTrajectories pairs;  // est as given (not aligned)
  Trajectory aligned_est;        // pairs.est after the alignment
  AlignmentResult alignment;
  // Scale of the Sim(3) fit on the same selection whatever the chosen alignment: the
  // factor that brings the estimate to metric; scale_error = |scale - 1|.
  double sim3_scale = 1.0;
  double scale_error = 0.0;
  std::vector<double> ape_translation_errors;  // m, one per pair
  ErrorStatistics ape_translation;             // m
  ErrorStatistics ape_rotation_deg;            // degrees
  std::vector<RelativeErrorResult> relative;
  PerAxisError per_axis;
  Completeness completeness;
  std::optional<ScaleDrift> scale_drift;     // when asked for and two windows are usable
  std::optional<RunTrackingStats> tracking;  // from a stats.json, when given
  std::optional<MapAccuracy> map;            // when map points and a world are given
};

// Throws InputError (source `est_source`) when no pose pairs in time (no overlap), fewer
// than 3 pairs, or the alignment is degenerate.
TrajectoryEvaluation EvaluateTrajectory(const Trajectory& gt, const Trajectory& est,
                                        const std::string& label, const std::string& est_source,
                                        const EvaluationOptions& options);

}  // namespace arucoslam
