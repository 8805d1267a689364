// The experiments' outputs: the comparison table, the plots of every evaluated run, and a
// report in Markdown and HTML that shows both, with each run's notes.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/exe/experiments.h"
#include "arucoslam/io/trajectory_io.h"

namespace arucoslam {

// Writes table.txt, plots (*.svg), report.md and report.html into `dir`; with a world file
// also floor_plan.svg (the runs over the world's plan).
// `world` describes the world and its markers in a sentence (empty: left out).
void WriteExperimentsReport(const Trajectory& ground_truth, const std::vector<ExperimentRun>& runs,
                            const std::string& table, const std::filesystem::path& dir,
                            const std::optional<std::filesystem::path>& world_sdf = std::nullopt,
                            const std::string& world = "");

}  // namespace arucoslam
