#include "arucoslam/exe/experiments_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <functional>

#include "arucoslam/eval/report.h"
#include "arucoslam/exe/experiments_floor_plan.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

using RunValue = std::function<std::string(const ExperimentRun&)>;

std::string Metres(double value) { return fmt::format("{:.4f}", value); }

// One table row: a name and how to read the value off a run ("-" when not evaluated).
struct Row {
  std::string name;
  RunValue value;
};

// A SLAM count of the run, "-" for runs that have none.
RunValue Count(int ExperimentRun::*field) {
  return [field](const ExperimentRun& run) {
    return run.*field >= 0 ? std::to_string(run.*field) : std::string("-");
  };
}

std::vector<Row> TableRows() {
  const auto absolute = [](auto getter) {
    return [getter](const ExperimentRun& run) -> std::string {
      return run.absolute ? getter(*run.absolute) : "-";
    };
  };
  return {
      {"sequence", [](const ExperimentRun& run) { return run.sequence; }},
      {"available", [](const ExperimentRun& run) { return std::string(run.available ? "yes" : "no"); }},
      {"poses / frames covered",
       absolute([](const TrajectoryEvaluation& e) {
         return fmt::format("{:.1f}%", 100.0 * e.completeness.covered_fraction);
       })},
      {"longest gap (s)",
       absolute([](const TrajectoryEvaluation& e) { return fmt::format("{:.2f}", e.completeness.longest_gap); })},
      {"tracking losses", Count(&ExperimentRun::losses)},
      {"new maps after a loss", Count(&ExperimentRun::new_maps)},
      {"keyframes", Count(&ExperimentRun::keyframes)},
      {"ATE world frame RMSE (m)",
       absolute([](const TrajectoryEvaluation& e) { return Metres(e.ape_translation.rmse); })},
      {"ATE world frame max (m)",
       absolute([](const TrajectoryEvaluation& e) { return Metres(e.ape_translation.max); })},
      {"ATE Sim(3)-aligned RMSE (m)",
       [](const ExperimentRun& run) {
         return run.sim3 ? Metres(run.sim3->ape_translation.rmse) : std::string("-");
       }},
      {"scale error (Sim3 fit)",
       absolute([](const TrajectoryEvaluation& e) { return fmt::format("{:.2f}%", 100.0 * e.scale_error); })},
      {"mean |error| x (m)", absolute([](const TrajectoryEvaluation& e) { return Metres(e.per_axis.mean_abs.x()); })},
      {"mean |error| y (m)", absolute([](const TrajectoryEvaluation& e) { return Metres(e.per_axis.mean_abs.y()); })},
      {"mean |error| z (m)", absolute([](const TrajectoryEvaluation& e) { return Metres(e.per_axis.mean_abs.z()); })},
      {"rotation error RMSE (deg)",
       absolute([](const TrajectoryEvaluation& e) { return fmt::format("{:.3f}", e.ape_rotation_deg.rmse); })},
      {"map points (as evaluated)",
       [](const ExperimentRun& run) {
         return run.map_accuracy ? std::to_string(run.map_accuracy->num_points) : std::string("-");
       }},
      {"map point to surface, median (m)",
       [](const ExperimentRun& run) {
         return run.map_accuracy ? Metres(run.map_accuracy->median) : std::string("-");
       }},
      {"map points within 5 cm of a surface",
       [](const ExperimentRun& run) {
         return run.map_accuracy
                    ? fmt::format("{:.1f}%", 100.0 * run.map_accuracy->fraction_within)
                    : std::string("-");
       }},
      {"median time per frame (ms)",
       [](const ExperimentRun& run) {
         return run.available ? fmt::format("{:.1f}", run.median_frame_ms) : std::string("-");
       }},
  };
}

std::string NotesMarkdown(const std::vector<ExperimentRun>& runs) {
  std::string notes;
  for (const ExperimentRun& run : runs) {
    notes += fmt::format("- **{}** ({}): {}\n", run.label, run.sequence,
                         run.note.empty() ? "evaluated" : run.note);
  }
  return notes;
}

std::string MarkdownTable(const std::vector<ExperimentRun>& runs) {
  std::string text = "| metric |";
  for (const ExperimentRun& run : runs) text += " " + run.label + " |";
  text += "\n|---|";
  for (std::size_t i = 0; i < runs.size(); ++i) text += "---|";
  text += "\n";
  for (const Row& row : TableRows()) {
    text += "| " + row.name + " |";
    for (const ExperimentRun& run : runs) text += " " + row.value(run) + " |";
    text += "\n";
  }
  return text;
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string HtmlReport(const std::vector<ExperimentRun>& runs,
                       const std::vector<std::string>& plot_files, const std::string& world) {
  std::string html =
      "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>ArucoSLAM experiments</title>"
      "<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto}"
      "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:4px 8px;"
      "text-align:right}td:first-child,th:first-child{text-align:left}</style></head><body>\n"
      "<h1>ArucoSLAM experiments</h1>\n";
  if (!world.empty()) html += "<p>World: " + HtmlEscape(world) + "</p>\n";
  html += "<table>\n<tr><th>metric</th>";
  for (const ExperimentRun& run : runs) html += "<th>" + HtmlEscape(run.label) + "</th>";
  html += "</tr>\n";
  for (const Row& row : TableRows()) {
    html += "<tr><td>" + HtmlEscape(row.name) + "</td>";
    for (const ExperimentRun& run : runs) html += "<td>" + HtmlEscape(row.value(run)) + "</td>";
    html += "</tr>\n";
  }
  html += "</table>\n<h2>Runs</h2>\n<ul>\n";
  for (const ExperimentRun& run : runs) {
    html += "<li><b>" + HtmlEscape(run.label) + "</b> (" + HtmlEscape(run.sequence) + "): " +
            HtmlEscape(run.note.empty() ? "evaluated" : run.note) + "</li>\n";
  }
  html += "</ul>\n<h2>Plots</h2>\n";
  for (const std::string& file : plot_files) {
    html += "<p><img src=\"" + file + "\" alt=\"" + file + "\" style=\"max-width:100%\"></p>\n";
  }
  return html + "</body></html>\n";
}

}  // namespace

std::string FormatExperimentsTable(const std::vector<ExperimentRun>& runs) {
  std::vector<std::vector<std::string>> cells;
  std::vector<std::string> header = {"metric"};
  for (const ExperimentRun& run : runs) header.push_back(run.label);
  cells.push_back(header);
  for (const Row& row : TableRows()) {
    std::vector<std::string> line = {row.name};
    for (const ExperimentRun& run : runs) line.push_back(row.value(run));
    cells.push_back(line);
  }
  std::vector<std::size_t> widths(header.size(), 0);
  for (const auto& line : cells) {
    for (std::size_t c = 0; c < line.size(); ++c) widths[c] = std::max(widths[c], line[c].size());
  }
  std::string text;
  for (std::size_t r = 0; r < cells.size(); ++r) {
    for (std::size_t c = 0; c < cells[r].size(); ++c) {
      text += c == 0 ? fmt::format("{:<{}}", cells[r][c], widths[c])
                     : fmt::format("  {:>{}}", cells[r][c], widths[c]);
    }
    text += "\n";
    if (r == 0) text += std::string(text.size() - 1, '-') + "\n";
  }
  return text;
}

void WriteExperimentsReport(const Trajectory& ground_truth, const std::vector<ExperimentRun>& runs,
                            const std::string& table, const std::filesystem::path& dir,
                            const std::optional<std::filesystem::path>& world_sdf,
                            const std::string& world) {
  WriteTextFileAtomically(dir / "table.txt", table);
  std::vector<TrajectoryEvaluation> absolute;
  std::vector<TrajectoryEvaluation> aligned;
  for (const ExperimentRun& run : runs) {
    if (run.absolute) absolute.push_back(*run.absolute);
    if (run.sim3) aligned.push_back(*run.sim3);
  }
  std::vector<std::string> plot_files;
  // World frame (what a world-anchored system is judged by), then Sim(3)-aligned.
  const auto write_plots = [&](const std::vector<TrajectoryEvaluation>& evaluations,
                               const std::string& prefix) {
    if (evaluations.empty()) return;
    for (const auto& [name, svg] : MakeEvaluationPlots(ground_truth, evaluations)) {
      WriteTextFileAtomically(dir / (prefix + name), svg);
      plot_files.push_back(prefix + name);
    }
  };
  if (world_sdf) {
    WriteTextFileAtomically(dir / "floor_plan.svg", FloorPlanSvg(*world_sdf, ground_truth, runs));
    plot_files.push_back("floor_plan.svg");
  }
  write_plots(absolute, "world_");
  write_plots(aligned, "sim3_aligned_");
  std::string markdown = "# ArucoSLAM experiments\n\n" +
                         (world.empty() ? "" : "World: " + world + "\n\n") +
                         MarkdownTable(runs) + "\n## Runs\n\n" +
                         NotesMarkdown(runs) + "\n## Plots\n\n";
  for (const std::string& file : plot_files) markdown += "![" + file + "](" + file + ")\n\n";
  WriteTextFileAtomically(dir / "report.md", markdown);
  WriteTextFileAtomically(dir / "report.html", HtmlReport(runs, plot_files, world));
}

}  // namespace arucoslam
