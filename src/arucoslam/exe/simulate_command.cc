// `arucoslam simulate`: renders a world (SDF) along a path (path.json, taught or repeat run)
// into a EuRoC-layout sequence with exact ground truth, all-or-nothing.
#include <cstdio>
#include <memory>
#include <string>

#include "arucoslam/exe/command.h"
#include "arucoslam/io/calibration.h"
#include "arucoslam/io/path_json.h"
#include "arucoslam/sim/dataset_writer.h"
#include "arucoslam/sim/default_camera.h"
#include "arucoslam/sim/path.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

struct SimulateArgs {
  std::string world;
  std::string path;
  std::string out;
  std::string run = "repeat";
  std::string camera;        // calibration file; empty: the default camera
  double max_seconds = 0.0;  // 0: the whole path
  DatasetWriterOptions writer;
  bool quiet = false;
};


void CheckArgs(const SimulateArgs& args) {
  const RenderOptions& render = args.writer.render;
  if (!(render.noise_sigma >= 0.0 && render.noise_sigma <= 50.0)) {
    throw InputError("--noise", "expected 0 to 50 grey levels");
  }
  if (!(args.writer.exposure_time_s >= 0.0 && args.writer.exposure_time_s <= 0.1)) {
    throw InputError("--blur", "expected an exposure time of 0 to 0.1 seconds");
  }
  if (args.writer.motion_blur_samples < 2 || args.writer.motion_blur_samples > 64) {
    throw InputError("--blur-samples", "expected 2 to 64");
  }
  if (!(render.exposure_variation >= 0.0 && render.exposure_variation < 1.0)) {
    throw InputError("--exposure-variation", "expected 0 to less than 1");
  }
  if (render.msaa_samples < 1 || render.msaa_samples > 16) {
    throw InputError("--msaa", "expected 1 to 16 samples");
  }
  if (!(args.max_seconds >= 0.0)) throw InputError("--max-seconds", "expected >= 0");
}

void RunSimulate(SimulateArgs args) {
  CheckArgs(args);
  if (args.run != "teach" && args.run != "repeat") {
    throw InputError("--run", "expected teach or repeat, found '" + args.run + "'");
  }
  RequireFile(args.world, "world SDF file");
  const PathSpec spec = ReadPathJson(args.path);
  CameraModel camera = args.camera.empty() ? DefaultSimulatorCamera() : ReadCameraModel(args.camera);
  camera.rate_hz = spec.options.camera_rate_hz;  // the path samples poses at this rate
  std::vector<TimedPose> poses =
      GenerateCameraPath(spec, args.run == "teach" ? PathRun::kTeach : PathRun::kRepeat);
  if (args.max_seconds > 0.0) {
    while (!poses.empty() && poses.back().time_s > args.max_seconds) poses.pop_back();
  }
  args.writer.progress = !args.quiet;
  const DatasetSummary summary =
      WriteSimulatedSequence(args.world, camera, poses, args.out, args.writer);
  std::printf("wrote %s: %zu frames (%.1f s of driving, %s run) in %.1f s, %.1f frames/s (%s)\n",
              args.out.c_str(), summary.frames, summary.duration_s, args.run.c_str(),
              summary.wall_time_s, summary.frames_per_second, summary.renderer.c_str());
}

}  // namespace

void AddSimulateCommand(CLI::App& app, int& exit_status) {
  auto args = std::make_shared<SimulateArgs>();
  args->writer = DefaultSensorOptions();  // the experiments' sensor
  CLI::App* simulate = app.add_subcommand(
      "simulate", "Render a sequence along a path through a world: EuRoC layout with ground "
                  "truth, markers.json and world.sdf");
  simulate->add_option("--world", args->world, "world SDF file (e.g. from `world factory`)")
      ->required();
  simulate->add_option("--path", args->path, "path.json with the taught route")->required();
  simulate->add_option("--out", args->out, "output sequence folder (replaced)")->required();
  simulate->add_option("--run", args->run, "teach (the route itself) or repeat (retraced "
                                           "with a small lateral deviation)")
      ->capture_default_str();
  simulate->add_option("--camera", args->camera,
                       "calibration file (EuRoC sensor.yaml, ORB-SLAM3 or ROS YAML); "
                       "default 640x480, 460 px focal length")
      ->check(CLI::ExistingFile);
  simulate->add_option("--max-seconds", args->max_seconds,
                       "render only the first seconds of the path (0: all)")
      ->capture_default_str();
  simulate->add_option("--noise", args->writer.render.noise_sigma,
                       "Gaussian sensor noise, grey levels")
      ->capture_default_str();
  simulate->add_option("--noise-seed", args->writer.render.noise_seed, "seed of the noise")
      ->capture_default_str();
  simulate->add_option("--exposure-variation", args->writer.render.exposure_variation,
                       "relative amplitude of slow exposure changes")
      ->capture_default_str();
  simulate->add_option("--blur", args->writer.exposure_time_s,
                       "exposure time for motion blur, seconds (0: none)")
      ->capture_default_str();
  simulate->add_option("--blur-samples", args->writer.motion_blur_samples,
                       "renders averaged per frame when --blur > 0")
      ->capture_default_str();
  simulate->add_option("--msaa", args->writer.render.msaa_samples,
                       "multisample anti-aliasing samples per pixel")
      ->capture_default_str();
  simulate->add_flag("--depth", args->writer.write_depth,
                     "also write depth images (mav0/depth0, 16-bit millimetres)");
  simulate->add_flag("--quiet", args->quiet, "no progress line");
  simulate->callback([args, &exit_status] {
    RunSimulate(*args);
    exit_status = kExitOk;
  });
}

}  // namespace arucoslam
