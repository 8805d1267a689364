// `arucoslam run`: monocular SLAM over a sequence (EuRoC layout, TUM RGB-D folder or image
// folder) -> trajectory.tum, keyframes.tum, map.ply and stats.json in one output folder.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "arucoslam/exe/command.h"
#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/io/slam_output.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {
namespace {

struct RunArgs {
  std::string dataset;
  std::string out;
  std::string camera;
  bool no_markers = false;
  bool blocking = false;
  bool quiet = false;
  int num_features = 1000;
  double rate_hz = 0.0;
};

Trajectory ToTrajectory(const std::vector<StampedPose>& poses) {
  Trajectory trajectory;
  for (const StampedPose& pose : poses) trajectory.Add(pose.timestamp_s, pose.world_from_cam);
  return trajectory;
}

SlamRunStats MakeStats(const RunArgs& args, const Dataset& dataset, const System& system,
                       bool markers, double wall_time_s) {
  const SystemStats stats = system.Stats();
  SlamRunStats out;
  out.dataset = args.dataset;
  out.layout = DatasetLayoutName(dataset.layout());
  out.blocking = args.blocking;
  out.markers = markers;
  out.frames = stats.num_frames;
  out.frames_tracked = stats.num_tracked;
  out.frames_lost = stats.num_lost;
  out.losses = stats.num_losses;
  out.initialization_attempts = stats.num_initialization_attempts;
  out.initializations = stats.num_initializations;
  out.resets = stats.num_resets;
  out.keyframes_inserted = stats.num_keyframes_inserted;
  out.keyframes = static_cast<int>(system.map().NumKeyframes());
  out.map_points = static_cast<int>(system.map().NumMapPoints());
  out.wall_time_s = wall_time_s;
  out.peak_memory_bytes = PeakMemoryBytes();
  out.timings_ms = {{"extraction", stats.extraction_ms.Summarize()},
                    {"tracking", stats.tracking_ms.Summarize()},
                    {"frame", stats.frame_ms.Summarize()},
                    {"local_mapping", stats.local_mapping_ms.Summarize()}};
  return out;
}

int RunSlam(const RunArgs& args) {
  if (args.num_features < 100) {
    throw InputError("--features", "expected at least 100, got " + std::to_string(args.num_features));
  }
  if (args.rate_hz < 0.0) throw InputError("--rate", "expected a rate >= 0 Hz");
  DatasetOptions dataset_options;
  dataset_options.camera_path = args.camera;
  dataset_options.rate_hz = args.rate_hz;
  const Dataset dataset = Dataset::Open(args.dataset, dataset_options);
  if (std::filesystem::exists(args.out) && !std::filesystem::is_directory(args.out)) {
    throw InputError(args.out, "exists and is not a directory");
  }
  // Marker fusion comes with a later stage of the system; a marker map is noted, not used.
  const bool markers = false;
  SystemOptions options;
  options.blocking = args.blocking;
  options.extractor.num_features = args.num_features;
  // EXPERIMENT-TOGGLES
  if (std::getenv("EXP_NOFUSE")) options.mapper.fusion_neighbours = 0;
  if (std::getenv("EXP_NOCULL")) options.mapper.cull_keyframes = false;
  if (std::getenv("EXP_MINF")) options.keyframes.min_frames_between = std::atoi(std::getenv("EXP_MINF"));
  if (std::getenv("EXP_FIXED")) options.mapper.bundle_adjustment.min_fixed_keyframes = std::atoi(std::getenv("EXP_FIXED"));
  if (std::getenv("EXP_NOBA")) options.mapper.run_bundle_adjustment = false;
  StagedDirectory staged(args.out);
  const Stopwatch wall;
  System system(dataset.camera(), options);
  const bool progress = !args.quiet;
  for (std::size_t i = 0; i < dataset.size(); ++i) {
    const FrameReport report = system.ProcessImage(dataset.LoadImage(i), dataset.frame(i).timestamp_s);
    if (progress && (i % 10 == 0 || i + 1 == dataset.size())) {
      std::fprintf(stderr, "\rframe %zu/%zu  %-15s keyframes %zu  points %zu", i + 1,
                   dataset.size(), TrackingStateName(report.state).c_str(),
                   system.map().NumKeyframes(), system.map().NumMapPoints());
      std::fflush(stderr);
    }
  }
  system.Finish();
  if (progress) std::fprintf(stderr, "\n");
  const SlamRunStats stats = MakeStats(args, dataset, system, markers, wall.ElapsedSeconds());
  WriteSlamOutput(staged.path(), ToTrajectory(system.Trajectory()),
                  ToTrajectory(system.KeyframePoses()), system.MapPoints(), stats);
  staged.Commit();
  const SystemStats timing = system.Stats();
  std::printf(
      "%d frames, %d tracked (%.1f%%), %d losses, %d keyframes, %d points; tracking median "
      "%.1f ms, local mapping median %.1f ms; %.1f s -> %s\n",
      stats.frames, stats.frames_tracked,
      stats.frames > 0 ? 100.0 * stats.frames_tracked / stats.frames : 0.0, stats.losses,
      stats.keyframes, stats.map_points, timing.tracking_ms.Summarize().median,
      timing.local_mapping_ms.Summarize().median, stats.wall_time_s, args.out.c_str());
  if (stats.initializations == 0) std::printf("map not initialised (no camera motion found)\n");
  return kExitOk;
}

}  // namespace

void AddRunCommand(CLI::App& app, int& exit_status) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* run = app.add_subcommand(
      "run", "SLAM on a sequence -> trajectory.tum, keyframes.tum, map.ply, stats.json");
  run->add_option("--dataset", args->dataset,
                  "the sequence: EuRoC layout (mav0/cam0), TUM RGB-D folder or image folder")
      ->required();
  run->add_option("--out", args->out, "output folder (replaced only when the run succeeds)")
      ->required();
  run->add_option("--camera", args->camera,
                  "calibration file (EuRoC sensor.yaml, ORB-SLAM3 settings or ROS camera_info); "
                  "required for TUM and image folders");
  run->add_flag("--no-markers", args->no_markers, "ignore the sequence's markers.json");
  run->add_flag("--blocking", args->blocking,
                "track and map each frame in turn on one thread (deterministic)");
  run->add_flag("--quiet", args->quiet, "no progress line");
  run->add_option("--features", args->num_features, "ORB features per image")
      ->capture_default_str();
  run->add_option("--rate", args->rate_hz, "image folder frame rate in Hz (0: from the camera)")
      ->capture_default_str();
  run->callback([args, &exit_status] { exit_status = RunSlam(*args); });
}

}  // namespace arucoslam
