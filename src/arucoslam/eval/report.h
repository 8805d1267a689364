// Reports of one or several trajectory evaluations: a plain-text table (estimates as
// columns, for comparing experiments), results.json, and the SVG plots.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "arucoslam/eval/evaluation.h"

namespace arucoslam {

// Metrics as rows, one column per evaluation.
std::string FormatEvaluationTable(const std::vector<TrajectoryEvaluation>& evaluations);

// results.json: {"format": "arucoslam.eval/1", "ground_truth": ..., "options": {...},
// "estimates": [{"label", "file", "pairs", "alignment": {...}, "ape": {...}, "rpe": [...],
// "per_axis": {...}, "scale": {...}, "completeness": {...}, "tracking"?, "map"?}]}.
// Statistics objects hold count, rmse, mean, median, std, min, max, sse.
std::string FormatResultsJson(const std::vector<TrajectoryEvaluation>& evaluations,
                              const std::vector<std::string>& est_files, const std::string& gt_file,
                              const EvaluationOptions& options);

// The plots as (file name, SVG text): trajectory_top_down.svg (the ground truth and every
// aligned estimate in the plane of the two axes along which the ground truth spreads most:
// x-y in a z-up world), ape_over_time.svg, per_axis_error.svg (|dx|, |dy|, |dz| over time,
// one panel per axis, samples of --at marked). Lines break where tracking left a gap.
std::vector<std::pair<std::string, std::string>> MakeEvaluationPlots(
    const Trajectory& gt, const std::vector<TrajectoryEvaluation>& evaluations);

}  // namespace arucoslam
