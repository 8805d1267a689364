// RunSlamOnDataset: one SLAM run over a whole sequence, shared by `run` and `experiments`:
// feeds every image to the System, then writes trajectory.tum, keyframes.tum, map.ply and
// stats.json into an output folder (all-or-nothing).
#pragma once

#include <filesystem>
#include <string>

#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/io/slam_output.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/pipeline/system.h"

namespace arucoslam {

struct SlamRunResult {
  Trajectory trajectory;  // every frame with a pose, world_from_cam
  Trajectory keyframes;
  SlamRunStats stats;
  SystemStats timing;
  std::vector<Eigen::Vector3d> map_points;  // as written to map.ply
};

// `dataset_label` names the dataset in stats.json; `markers` says whether the run used the
// sequence's marker map. A progress line goes to stderr when `progress` is set.
SlamRunResult RunSlamOnDataset(const Dataset& dataset, const std::string& dataset_label,
                               const SystemOptions& options, bool markers,
                               const std::filesystem::path& out_dir, bool progress);

// One summary line of a finished run.
std::string SlamRunSummary(const SlamRunResult& result, const std::string& out_dir);

}  // namespace arucoslam
