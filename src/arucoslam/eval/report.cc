#include "arucoslam/eval/report.h"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>

namespace arucoslam {
namespace {

using Row = std::pair<std::string, std::vector<std::string>>;

std::string Fixed(double value, int decimals) { return fmt::format("{:.{}f}", value, decimals); }

std::vector<Row> StatisticRows(const std::vector<TrajectoryEvaluation>& evaluations) {
  std::vector<Row> rows;
  const auto add = [&](const std::string& name, auto value_of) {
    Row row{name, {}};
    for (const TrajectoryEvaluation& e : evaluations) row.second.push_back(value_of(e));
    rows.push_back(std::move(row));
  };
  add("poses est / gt / paired", [](const TrajectoryEvaluation& e) {
    return fmt::format("{} / {} / {}", e.num_est_poses, e.num_gt_poses, e.pairs.size());
  });
  add("alignment",
      [](const TrajectoryEvaluation& e) { return AlignmentModeName(e.alignment.mode); });
  const std::pair<const char*, double ErrorStatistics::*> fields[] = {
      {"rmse", &ErrorStatistics::rmse},     {"mean", &ErrorStatistics::mean},
      {"median", &ErrorStatistics::median}, {"std", &ErrorStatistics::std},
      {"min", &ErrorStatistics::min},       {"max", &ErrorStatistics::max}};
  for (const auto& [name, field] : fields) {
    add(fmt::format("APE translation {} [m]", name),
        [field](const TrajectoryEvaluation& e) { return Fixed(e.ape_translation.*field, 4); });
  }
  add("APE rotation rmse [deg]",
      [](const TrajectoryEvaluation& e) { return Fixed(e.ape_rotation_deg.rmse, 3); });
  add("APE rotation max [deg]",
      [](const TrajectoryEvaluation& e) { return Fixed(e.ape_rotation_deg.max, 3); });
  for (std::size_t k = 0; k < evaluations.front().relative.size(); ++k) {
    const RelativeErrorOptions& o = evaluations.front().relative[k].options;
    const std::string delta = fmt::format("{:g} {}", o.delta, DeltaUnitName(o.unit));
    add(fmt::format("RPE {} translation rmse [m]", delta),
        [k](const TrajectoryEvaluation& e) { return Fixed(e.relative[k].translation.rmse, 4); });
    add(fmt::format("RPE {} rotation rmse [deg]", delta),
        [k](const TrajectoryEvaluation& e) { return Fixed(e.relative[k].rotation_deg.rmse, 3); });
  }
  const char* axes[] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    add(fmt::format("|d{}| mean / std [m]", axes[a]), [a](const TrajectoryEvaluation& e) {
      return fmt::format("{:.4f} / {:.4f}", e.per_axis.mean_abs[a], e.per_axis.std_abs[a]);
    });
  }
  return rows;
}

std::vector<Row> RunRows(const std::vector<TrajectoryEvaluation>& evaluations) {
  std::vector<Row> rows;
  const auto add = [&](const std::string& name, auto value_of) {
    Row row{name, {}};
    for (const TrajectoryEvaluation& e : evaluations) row.second.push_back(value_of(e));
    rows.push_back(std::move(row));
  };
  add("Sim3 scale / scale error", [](const TrajectoryEvaluation& e) {
    return fmt::format("{:.4f} / {:.2f}%", e.sim3_scale, 100.0 * e.scale_error);
  });
  const bool any_drift =
      std::any_of(evaluations.begin(), evaluations.end(),
                  [](const TrajectoryEvaluation& e) { return e.scale_drift.has_value(); });
  if (any_drift) {
    add("scale drift: last / first window - 1", [](const TrajectoryEvaluation& e) {
      return e.scale_drift ? fmt::format("{:+.2f}%", 100.0 * e.scale_drift->last_over_first)
                           : std::string("-");
    });
    add("windowed scale min / max", [](const TrajectoryEvaluation& e) {
      return e.scale_drift ? fmt::format("{:.4f} / {:.4f}", e.scale_drift->min, e.scale_drift->max)
                           : std::string("-");
    });
  }
  add("completeness [% of gt time]", [](const TrajectoryEvaluation& e) {
    return Fixed(100.0 * e.completeness.covered_fraction, 1);
  });
  add("longest gap [s]",
      [](const TrajectoryEvaluation& e) { return Fixed(e.completeness.longest_gap, 2); });
  add("losses / relocalisations", [](const TrajectoryEvaluation& e) {
    return e.tracking ? fmt::format("{} / {}", e.tracking->losses, e.tracking->relocalisations)
                      : std::string("-");
  });
  const bool any_map = std::any_of(evaluations.begin(), evaluations.end(),
                                   [](const TrajectoryEvaluation& e) { return e.map.has_value(); });
  if (any_map) {
    add("map points", [](const TrajectoryEvaluation& e) {
      return e.map ? std::to_string(e.map->num_points) : std::string("-");
    });
    add("map error median / p90 [m]", [](const TrajectoryEvaluation& e) {
      return e.map ? fmt::format("{:.3f} / {:.3f}", e.map->median, e.map->percentile_90)
                   : std::string("-");
    });
    add("map points within 5 cm [%]", [](const TrajectoryEvaluation& e) {
      return e.map ? Fixed(100.0 * e.map->fraction_within, 1) : std::string("-");
    });
  }
  return rows;
}

}  // namespace

std::string FormatEvaluationTable(const std::vector<TrajectoryEvaluation>& evaluations) {
  if (evaluations.empty()) return "";
  std::vector<Row> rows = StatisticRows(evaluations);
  for (Row& row : RunRows(evaluations)) rows.push_back(std::move(row));
  std::size_t name_width = 6;
  std::vector<std::size_t> widths;
  for (const TrajectoryEvaluation& e : evaluations) widths.push_back(e.label.size());
  for (const Row& row : rows) {
    name_width = std::max(name_width, row.first.size());
    for (std::size_t c = 0; c < row.second.size(); ++c) {
      widths[c] = std::max(widths[c], row.second[c].size());
    }
  }
  std::string out = fmt::format("{:<{}}", "metric", name_width);
  for (std::size_t c = 0; c < evaluations.size(); ++c) {
    out += fmt::format("  {:>{}}", evaluations[c].label, widths[c]);
  }
  out += "\n" + std::string(out.size() - 1, '-') + "\n";
  for (const Row& row : rows) {
    out += fmt::format("{:<{}}", row.first, name_width);
    for (std::size_t c = 0; c < row.second.size(); ++c) {
      out += fmt::format("  {:>{}}", row.second[c], widths[c]);
    }
    out += "\n";
  }
  return out;
}

}  // namespace arucoslam
