// For the exe/ tests: a small factory world (one 8 m aisle, four 0.3 m markers per dock) and
// sequences driven along its aisle, made with the built binary: the default camera at half
// size (320x240), 15 Hz, no MSAA, so a few seconds of driving render and run in seconds.
#pragma once

#include <filesystem>
#include <string>

#include "arucoslam/exe/command_test_util.h"
#include "arucoslam/geometry/camera.h"
#include "arucoslam/io/calibration.h"
#include "arucoslam/io/path_json.h"

namespace arucoslam::testing_util {

// Writes the world to dir/world and the camera to dir/camera.yaml.
inline SplitCommandResult MakeAisleWorld(const std::filesystem::path& dir) {
  WriteEuRoCSensorYaml(PinholeCamera(320, 240, 230.0), dir / "camera.yaml");
  return RunArucoslamSplit(
      "world factory --seed 3 --aisles 1 --aisle-length 8 --wall-markers 0 "
      "--markers-per-dock 4 --marker-size 0.3 --out " +
          (dir / "world").string(),
      dir);
}

// Renders dir/seq_<name>: the aisle from x = start_x m to 12.5 m, `run` teach (the route) or
// repeat (up to 8 cm off to the side).
inline SplitCommandResult SimulateAisle(const std::filesystem::path& dir, const std::string& name,
                                        double start_x, const std::string& run) {
  PathSpec spec = ReadPathJson(dir / "world" / "path.json");
  spec.options.camera_rate_hz = 15.0;
  spec.waypoints = {{start_x, 4.6, 0.0}, {12.5, 4.6, 0.0}};
  const std::filesystem::path path = dir / ("path_" + name + ".json");
  WritePathJson(path, spec);
  return RunArucoslamSplit("simulate --world " + (dir / "world" / "world.sdf").string() +
                               " --path " + path.string() + " --run " + run + " --camera " +
                               (dir / "camera.yaml").string() + " --msaa 1 --quiet --out " +
                               (dir / ("seq_" + name)).string(),
                           dir);
}

// Empties `dir` and makes the world, the camera and seq_a in it: the aisle from x = 6 m to
// 12.5 m, teach run (128 frames).
inline SplitCommandResult MakeAisleTeachSequence(const std::filesystem::path& dir) {
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const SplitCommandResult world = MakeAisleWorld(dir);
  if (world.status != 0) return world;
  return SimulateAisle(dir, "a", 6.0, "teach");
}

}  // namespace arucoslam::testing_util
