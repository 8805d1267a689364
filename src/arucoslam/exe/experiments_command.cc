// `arucoslam experiments` and `arucoslam demo`: the paper's three experiments on a world,
// and the same on the built-in default factory (what `make demo` runs).
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "arucoslam/exe/command.h"
#include "arucoslam/exe/default_vocabulary.h"
#include "arucoslam/exe/experiments.h"
#include "arucoslam/sim/factory_world.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

void PrintResult(const ExperimentsResult& result, const fs::path& out_dir) {
  std::printf("%s\n", result.table.c_str());
  for (const ExperimentRun& run : result.runs) {
    std::printf("%s: %s\n", run.label.c_str(), run.note.empty() ? "evaluated" : run.note.c_str());
  }
  std::printf("report: %s\n", (out_dir / "report.html").string().c_str());
}

// The default factory twice from one seed: with markers (at the docks and every metre along
// the corridor wall) and without. Returns the report's sentence on the world.
std::string WriteDefaultWorlds(std::uint32_t seed, const fs::path& with_markers,
                               const fs::path& without_markers) {
  FactoryOptions options;
  options.seed = seed;
  options.texture = TextureLevel::kLow;  // the paper's homogeneous environment
  fs::create_directories(with_markers);
  const FactoryWorld world = BuildFactoryWorld(options);
  WriteFactoryWorld(world, with_markers);
  std::size_t dock_markers = 0;
  for (const FactoryDock& dock : world.docks) dock_markers += dock.marker_ids.size();
  const std::string description = fmt::format(
      "the default factory (seed {}, low texture) with {} markers of {:.2f} m: {} at the docks "
      "and {} on the corridor wall, one every {:g} m as the ArucoSLAM authors' simulation has "
      "them (`world factory --wall-markers 0` leaves the docks only)",
      seed, world.markers.markers.size(), options.marker_size_m, dock_markers,
      world.markers.markers.size() - dock_markers, options.wall_marker_spacing_m);
  options.markers = false;
  fs::create_directories(without_markers);
  WriteFactoryWorld(BuildFactoryWorld(options), without_markers);
  return description;
}

}  // namespace

void AddExperimentsCommand(CLI::App& app, int& exit_status) {
  auto options = std::make_shared<ExperimentsOptions>();
  auto without = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(
      "experiments",
      "The paper's three experiments on a world (ArucoSLAM; keypoints only with markers in the "
      "scene; keypoints only without markers): render, run, evaluate, report");
  command->add_option("--world", options->world_dir, "world folder from `world factory`")->required();
  command->add_option("--world-without-markers", *without,
                      "the same world without markers (for experiment 3)");
  command->add_option("--out", options->out_dir, "output folder (replaced)")->required();
  command->add_option("--max-seconds", options->max_seconds,
                      "use only the first seconds of the route (0: all)")
      ->capture_default_str();
  command->add_option("--vocabulary", options->vocabulary,
                      "bag-of-words vocabulary of the SLAM runs (default: " +
                          std::string(kDefaultVocabularyName) + " shipped with arucoslam)");
  auto no_loop_closing = std::make_shared<bool>(false);
  command->add_flag("--no-loop-closing", *no_loop_closing,
                    "the SLAM runs do not close loops (relocalisation stays on)");
  auto no_ground_vehicle = std::make_shared<bool>(false);
  command->add_flag("--no-ground-vehicle", *no_ground_vehicle,
                    "run 1 without the ground-vehicle prior (`run --ground-vehicle`)");
  command->callback([options, without, no_loop_closing, no_ground_vehicle, &exit_status] {
    options->loop_closing = !*no_loop_closing;
    options->ground_vehicle = !*no_ground_vehicle;
    if (!without->empty()) options->world_without_markers_dir = *without;
    PrintResult(RunExperiments(*options), options->out_dir);
    exit_status = kExitOk;
  });
}

void AddDemoCommand(CLI::App& app, int& exit_status) {
  auto out = std::make_shared<std::string>("out/demo");
  auto seed = std::make_shared<std::uint32_t>(1);
  auto max_seconds = std::make_shared<double>(0.0);
  CLI::App* command = app.add_subcommand(
      "demo", "Everything on the built-in default: the factory world, its sequences, the three "
              "experiments, the table and the report (out/demo/)");
  command->add_option("--out", *out, "output folder (replaced)")->capture_default_str();
  command->add_option("--seed", *seed, "seed of the factory")->capture_default_str();
  command->add_option("--max-seconds", *max_seconds, "use only the first seconds of the route")
      ->capture_default_str();
  command->callback([out, seed, max_seconds, &exit_status] {
    StagedDirectory staged{fs::path(*out)};
    ExperimentsOptions options;
    options.world_dir = staged.path() / "world";
    options.world_without_markers_dir = staged.path() / "world_without_markers";
    options.out_dir = staged.path() / "experiments";
    options.max_seconds = *max_seconds;
    options.world_description =
        WriteDefaultWorlds(*seed, options.world_dir, *options.world_without_markers_dir);
    const ExperimentsResult result = RunExperiments(options);
    staged.Commit();
    PrintResult(result, fs::path(*out) / "experiments");
    exit_status = kExitOk;
  });
}

}  // namespace arucoslam
