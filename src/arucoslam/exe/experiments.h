// Experiments: the paper's comparison on one world — render the taught route's repeat run
// with and without markers, run each method on it, evaluate against the exact ground truth,
// and write a table, results.json, plots and a report (Markdown and HTML).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/eval/evaluation.h"
#include "arucoslam/eval/map_accuracy.h"
#include "arucoslam/sim/dataset_writer.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct ExperimentsOptions {
  // A folder from `arucoslam world factory`: world.sdf, path.json, markers.json.
  std::filesystem::path world_dir;
  // The same world without markers (run 3); none: run 3 is left out, and the report says so.
  std::optional<std::filesystem::path> world_without_markers_dir;
  std::filesystem::path out_dir;
  double max_seconds = 0.0;  // render only the first seconds of the route (0: all)
  DatasetWriterOptions render = DefaultSensorOptions();  // the sensor of `simulate`
  bool progress = true;
  // Bag-of-words vocabulary of the SLAM runs (relocalisation and loop closing, as `run`);
  // empty: the one shipped with arucoslam. `loop_closing` false: relocalisation only.
  std::filesystem::path vocabulary;
  bool loop_closing = true;
  // The route is a ground vehicle's: run 1 (the one in the marker world) holds its keyframes
  // near one camera height and tilt in the whole-map adjustment (`run --ground-vehicle`).
  bool ground_vehicle = true;
  // One sentence on the world and its markers for the report (empty: the number of markers
  // in world_dir's markers.json).
  std::string world_description;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("max_seconds", max_seconds, 0.0);
    check.Nested("render", render);
    return check.ok();
  }
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
  // SLAM runs only (-1 / empty otherwise), from the System.
  int losses = -1;          // transitions tracking -> lost
  int new_maps = -1;        // maps started after a long loss
  int keyframes = -1;       // keyframes output (keyframes.tum)
  Trajectory keyframe_poses;
  // Distance of the output map points to the nearest surface of the true world, after the
  // alignment of the evaluation shown for the run (world frame for run 1, Sim(3) for 2, 3).
  std::optional<MapAccuracy> map_accuracy;
  // The run's poses are in the world frame (markers); false: plots use the Sim(3) fit.
  bool in_world_frame = true;
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
