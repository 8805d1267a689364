// The experiments' floor-plan plot: the world's footprints seen from above (walls, racks,
// pillars) under the ground truth, each SLAM run's trajectory and keyframes, in metres.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "arucoslam/exe/experiments.h"
#include "arucoslam/io/trajectory_io.h"

namespace arucoslam {

// SVG of the plan of `world_sdf` (InputError for a bad file) with the runs drawn in the
// frame of their shown evaluation (world frame, or Sim(3)-aligned when not in the world).
std::string FloorPlanSvg(const std::filesystem::path& world_sdf, const Trajectory& ground_truth,
                         const std::vector<ExperimentRun>& runs);

}  // namespace arucoslam
