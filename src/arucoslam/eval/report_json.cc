// results.json of `arucoslam eval` (declared in report.h).
#include <nlohmann/json.hpp>

#include "arucoslam/eval/report.h"

namespace arucoslam {
namespace {

using nlohmann::json;

json StatisticsJson(const ErrorStatistics& s) {
  return {{"count", s.count}, {"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median},
          {"std", s.std},     {"min", s.min},   {"max", s.max},   {"sse", s.sse}};
}

json VectorJson(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

json PerAxisJson(const PerAxisError& per_axis) {
  json samples = json::array();
  for (const PerAxisSample& s : per_axis.samples) {
    json sample = {{"requested_time", s.requested_time}, {"found", s.found}};
    if (s.found) {
      sample["time"] = s.time;
      sample["gt_position"] = VectorJson(s.gt_position);
      sample["est_position"] = VectorJson(s.est_position);
      sample["abs_error"] = VectorJson(s.abs_error);
    }
    samples.push_back(sample);
  }
  return {{"unit", "m"},
          {"mean_abs", VectorJson(per_axis.mean_abs)},
          {"std_abs", VectorJson(per_axis.std_abs)},
          {"max_abs", VectorJson(per_axis.max_abs)},
          {"samples", samples}};
}

json EvaluationJson(const TrajectoryEvaluation& e, const std::string& file) {
  const Sim3& t = e.alignment.gt_from_est;
  json rpe = json::array();
  for (const RelativeErrorResult& r : e.relative) {
    rpe.push_back({{"delta", r.options.delta},
                   {"delta_unit", DeltaUnitName(r.options.unit)},
                   {"all_pairs", r.options.all_pairs},
                   {"translation_m", StatisticsJson(r.translation)},
                   {"rotation_deg", StatisticsJson(r.rotation_deg)}});
  }
  const Completeness& c = e.completeness;
  json out = {
      {"label", e.label},
      {"file", file},
      {"poses",
       {{"estimate", e.num_est_poses},
        {"ground_truth", e.num_gt_poses},
        {"pairs", e.pairs.size()}}},
      {"alignment",
       {{"mode", AlignmentModeName(e.alignment.mode)},
        {"pairs_fitted", e.alignment.num_fitted},
        {"scale", t.scale},
        {"rotation_xyzw",
         json::array({t.rotation.x(), t.rotation.y(), t.rotation.z(), t.rotation.w()})},
        {"translation", VectorJson(t.translation)}}},
      {"ape",
       {{"translation_m", StatisticsJson(e.ape_translation)},
        {"rotation_deg", StatisticsJson(e.ape_rotation_deg)}}},
      {"rpe", rpe},
      {"per_axis", PerAxisJson(e.per_axis)},
      {"scale", {{"sim3_scale", e.sim3_scale}, {"scale_error", e.scale_error}}},
      {"completeness",
       {{"covered_fraction", c.covered_fraction},
        {"covered_s", c.covered_duration},
        {"ground_truth_s", c.gt_duration},
        {"longest_gap_s", c.longest_gap},
        {"longest_gap_start_s", c.longest_gap_start},
        {"gaps", c.num_gaps},
        {"gap_threshold_s", c.max_gap_used}}},
  };
  if (e.scale_drift) {
    json windows = json::array();
    for (const ScaleDriftWindow& w : e.scale_drift->windows) {
      windows.push_back({{"start_s", w.start_s},
                         {"end_s", w.end_s},
                         {"pairs", w.num_pairs},
                         {"estimate_per_truth", w.estimate_per_truth}});
    }
    out["scale_drift"] = {{"last_over_first", e.scale_drift->last_over_first},
                          {"min", e.scale_drift->min},
                          {"max", e.scale_drift->max},
                          {"windows", windows}};
  }
  if (e.tracking) {
    out["tracking"] = {{"losses", e.tracking->losses},
                       {"relocalisations", e.tracking->relocalisations}};
  }
  if (e.map) {
    out["map"] = {{"points", e.map->num_points},
                  {"median_m", e.map->median},
                  {"percentile_90_m", e.map->percentile_90},
                  {"mean_m", e.map->mean},
                  {"fraction_within", e.map->fraction_within},
                  {"within_m", e.map->inlier_distance}};
  }
  return out;
}

}  // namespace

std::string FormatResultsJson(const std::vector<TrajectoryEvaluation>& evaluations,
                              const std::vector<std::string>& est_files, const std::string& gt_file,
                              const EvaluationOptions& options) {
  json estimates = json::array();
  for (std::size_t i = 0; i < evaluations.size(); ++i) {
    estimates.push_back(EvaluationJson(evaluations[i], i < est_files.size() ? est_files[i] : ""));
  }
  json root = {
      {"format", "arucoslam.eval/1"},
      {"ground_truth", gt_file},
      {"options",
       {{"max_time_difference_s", options.association.max_time_difference},
        {"associate_by_index", options.associate_by_index},
        {"alignment", AlignmentModeName(options.alignment.mode)},
        {"align_first_poses", options.alignment.first_poses}}},
      {"estimates", estimates},
  };
  if (options.alignment.window_start) {
    root["options"]["align_window_start_s"] = *options.alignment.window_start;
  }
  if (options.alignment.window_end) {
    root["options"]["align_window_end_s"] = *options.alignment.window_end;
  }
  return root.dump(2) + "\n";
}

}  // namespace arucoslam
