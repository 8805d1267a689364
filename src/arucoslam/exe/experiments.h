// Experiments: the paper's comparison on one world — render the taught route's repeat run
// with and without markers, run each method on it, evaluate against the exact ground truth,
// and write a table, results.json, plots and a report (Markdown and HTML).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/eval/evaluation.h"
#include "arucoslam/sim/dataset_writer.h"

namespace arucoslam {

struct ExperimentsOptions {
  // A folder from `arucoslam world factory`: world.sdf, path.json, markers.json.
  std::filesystem::path world_dir;
  // The same world without markers (run 3); none: run 3 is left out, and the report says so.
  std::optional<std::filesystem::path> world_without_markers_dir;
  std::filesystem::path out_dir;
  double max_seconds = 0.0;  // render only the first seconds of the route (0: all)
  DatasetWriterOptions render;
  bool progress = true;

  bool Check() const { return max_seconds >= 0.0 && render.Check(); }
};

// One method's result on one sequence.
struct ExperimentRun {
  std::string label;            // as in the table
  std::string sequence;         // "with markers" / "without markers"
  bool available = false;       // false: the method is not built yet or could not run
  std::string note;             // why not available, or remarks
  std::optional<TrajectoryEvaluation> absolute;  // no alignment (world frame)
  std::optional<TrajectoryEvaluation> sim3;      // Sim(3)-aligned (keypoint-only runs)
  double median_frame_ms = 0.0;                  // per-frame processing time
};

struct ExperimentsResult {
  std::vector<ExperimentRun> runs;
  std::string table;  // the printed table
};

// Runs everything and writes out_dir all-or-nothing. Throws InputError for bad input.
ExperimentsResult RunExperiments(const ExperimentsOptions& options);

// The comparison table (methods as columns).
std::string FormatExperimentsTable(const std::vector<ExperimentRun>& runs);

}  // namespace arucoslam
