// `arucoslam world factory`: a procedural factory world (world.sdf, textures, marker PNGs,
// markers.json and the default taught route path.json) written all-or-nothing to --out.
#include <cstdio>
#include <memory>
#include <string>

#include "arucoslam/exe/command.h"
#include "arucoslam/sim/factory_world.h"
#include "arucoslam/sim/path.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

struct FactoryArgs {
  FactoryOptions options;
  std::string texture = "medium";
  std::string markers = "on";
  std::string motion = "robot";
  std::string out;
};

void RunFactory(FactoryArgs args) {
  if (args.markers != "on" && args.markers != "off") {
    throw InputError("--markers", "expected on or off, found '" + args.markers + "'");
  }
  args.options.markers = args.markers == "on";
  args.options.texture = TextureLevelFromName(args.texture);
  const FactoryOptions& o = args.options;
  if (o.aisles < 1 || o.aisles > 8) throw InputError("--aisles", "expected 1 to 8");
  if (!(o.aisle_length_m >= 6.0 && o.aisle_length_m <= 60.0)) {
    throw InputError("--aisle-length", "expected 6 to 60 metres");
  }
  if (!(o.marker_size_m > 0.05 && o.marker_size_m <= 1.0)) {
    throw InputError("--marker-size", "expected more than 0.05 and at most 1 metre");
  }
  if (o.markers_per_dock < 1 || o.markers_per_dock > 4) {
    throw InputError("--markers-per-dock", "expected 1 to 4");
  }
  if (!(o.camera_height_m >= 0.3 && o.camera_height_m <= 1.0)) {
    throw InputError("--camera-height", "expected 0.3 to 1.0 metres");
  }
  const PathMotion motion = PathMotionFromName(args.motion, "--motion");
  FactoryWorld world = BuildFactoryWorld(o);
  world.default_route.options = WithMotion(world.default_route.options, motion);
  const std::vector<RouteSample> route = PlanRoute(world.default_route);
  StagedDirectory out(args.out);
  WriteFactoryWorld(world, out.path());
  out.Commit();
  std::size_t visuals = 0;
  for (const FactoryModel& model : world.models) visuals += model.visuals.size();
  std::size_t dock_markers = 0;
  for (const FactoryDock& dock : world.docks) dock_markers += dock.marker_ids.size();
  const std::size_t wall_markers = world.markers.markers.size() - dock_markers;
  const std::string wall =
      wall_markers > 0 ? " and " + std::to_string(wall_markers) + " on the corridor wall" : "";
  std::printf(
      "wrote %s: hall %.1f x %.1f m, %zu models (%zu visuals), %zu textures, %zu markers at "
      "%zu docks%s; path.json: %.1f m, %.1f s\n",
      args.out.c_str(), world.hall_length_m, world.hall_width_m, world.models.size(), visuals,
      world.textures.size(), dock_markers, world.docks.size(), wall.c_str(), RouteLength(route),
      RouteDuration(route));
}

}  // namespace

void AddWorldCommand(CLI::App& app, int& exit_status) {
  CLI::App* world = app.add_subcommand("world", "Procedural worlds for the simulator");
  world->require_subcommand(1);
  auto args = std::make_shared<FactoryArgs>();
  CLI::App* factory = world->add_subcommand(
      "factory",
      "A factory hall (low-texture corridor, aisles of racks, machines, docks with "
      "ArUco markers): world.sdf, textures/, markers/, markers.json, path.json");
  factory->add_option("--seed", args->options.seed, "random seed (same seed, same files)")
      ->capture_default_str();
  factory->add_option("--out", args->out, "output folder (replaced)")->required();
  factory->add_option("--aisles", args->options.aisles, "aisles between rack rows, 1-8")
      ->capture_default_str();
  factory
      ->add_option("--aisle-length", args->options.aisle_length_m,
                   "length of the racks along an aisle, metres (6-60)")
      ->capture_default_str();
  factory->add_option("--texture", args->texture, "surface detail and clutter: low, medium, high")
      ->capture_default_str();
  factory->add_option("--markers", args->markers,
                      "markers at the docks and on the corridor wall (--wall-markers): on or off")
      ->capture_default_str();
  factory
      ->add_option("--marker-size", args->options.marker_size_m,
                   "side of a marker's black square, metres")
      ->capture_default_str();
  factory->add_option("--dictionary", args->options.dictionary, "ArUco dictionary name")
      ->capture_default_str();
  factory
      ->add_option("--markers-per-dock", args->options.markers_per_dock,
                   "markers side by side on each dock board, 1-4")
      ->capture_default_str();
  factory->add_flag("--corridor-end-markers", args->options.corridor_end_markers,
                    "one more marker board on the corridor's long wall at each end (the wall "
                    "the route faces while it turns there)");
  factory
      ->add_option("--wall-markers", args->options.wall_marker_spacing_m,
                   "marker boards along the corridor's long wall every this many metres, 1-20, "
                   "as the ArucoSLAM authors' simulation has them (0: none, markers at the docks "
                   "only)")
      ->capture_default_str();
  factory
      ->add_option("--camera-height", args->options.camera_height_m,
                   "height of the route's camera and of the marker centres, metres")
      ->capture_default_str();
  factory
      ->add_option("--motion", args->motion,
                   "how path.json drives the route: robot (1 m/s, 30 Hz) or car (up to 6 m/s, "
                   "10 Hz, as in driving datasets)")
      ->capture_default_str();
  factory->callback([args, &exit_status] {
    RunFactory(*args);
    exit_status = kExitOk;
  });
}

}  // namespace arucoslam
