// `arucoslam run`: monocular SLAM over a sequence (EuRoC layout, TUM RGB-D folder, KITTI
// odometry folder, image folder, video file or one image topic of a ROS 1 bag) or a live
// camera -> trajectory.tum, keyframes.tum, map.ply, stats.json (and with markers
// markers.json: the known markers and the ones mapped online) in one output folder; map reuse:
// --save-map writes the map file after the run, --load-map starts from one, --localize-only
// tracks against it without changing it. The SLAM's options: run's defaults, then a config file
// (--config, as --print-config writes it), then the flags that set options.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "arucoslam/exe/bag_feed.h"
#include "arucoslam/exe/command.h"
#include "arucoslam/exe/default_vocabulary.h"
#include "arucoslam/exe/slam_run.h"
#include "arucoslam/io/calibration.h"
#include "arucoslam/io/camera_source.h"
#include "arucoslam/io/config_file.h"
#include "arucoslam/io/frame_source.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/io/paced_source.h"
#include "arucoslam/io/read_ahead_source.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

struct RunArgs {
  std::string dataset;
  std::string device;  // a live camera instead of a dataset
  bool realtime = false;  // replay the dataset at its recorded rate, as a live camera
  std::size_t max_frames = 0;
  std::string out;
  std::string config;         // options file read over run's defaults
  bool print_config = false;  // write the options as YAML to stdout instead of running
  std::string camera;
  std::string image_topic;        // ROS bag only
  std::string camera_info_topic;  // ROS bag only
  std::string vocabulary;  // empty: the default one
  bool no_loop_closing = false;
  std::string markers;  // overrides the sequence's markers.json
  double marker_size_m = 0.0;
  bool no_markers = false;
  bool ground_vehicle = false;
  bool blocking = false;
  bool quiet = false;
  int num_features = 0;  // used when given (num_features_given): overrides the config file
  bool num_features_given = false;
  bool marker_size_given = false;  // --marker-size given: overrides the config file
  double rate_hz = 0.0;
  std::string save_map;
  std::string load_map;
  bool localize_only = false;
};

void CheckMapArgs(const RunArgs& args) {
  if (args.localize_only && args.load_map.empty()) {
    throw InputError("--localize-only", "needs --load-map FILE (the map to localise in)");
  }
  if (args.localize_only && !args.save_map.empty()) {
    throw InputError("--save-map", "not with --localize-only (the loaded map is not changed)");
  }
  if (!args.save_map.empty()) {
    const std::filesystem::path folder = std::filesystem::path(args.save_map).parent_path();
    if (!folder.empty()) RequireDirectory(folder, "folder for --save-map");
    if (std::filesystem::is_directory(args.save_map)) {
      throw InputError(args.save_map, "--save-map names a folder, expected a file");
    }
  }
}

// Set by SIGINT: the run stops reading frames and still writes its outputs.
std::atomic<bool> g_stop_requested{false};

extern "C" void RequestStop(int) {
  g_stop_requested = true;
  std::signal(SIGINT, SIG_DFL);  // a second Ctrl-C ends the program at once
}

// Routes SIGINT to RequestStop while a run is in progress.
class StopOnInterrupt {
 public:
  StopOnInterrupt() : previous_(std::signal(SIGINT, RequestStop)) { g_stop_requested = false; }
  ~StopOnInterrupt() { std::signal(SIGINT, previous_); }
  StopOnInterrupt(const StopOnInterrupt&) = delete;
  StopOnInterrupt& operator=(const StopOnInterrupt&) = delete;

 private:
  void (*previous_)(int);
};

std::unique_ptr<FrameSource> OpenSource(const RunArgs& args) {
  if (args.dataset.empty() == args.device.empty()) {
    throw InputError("--dataset", "give either --dataset PATH or --device CAMERA");
  }
  const bool bag = args.device.empty() && IsBagDataset(args.dataset);
  if (!bag && (!args.image_topic.empty() || !args.camera_info_topic.empty())) {
    throw InputError(args.image_topic.empty() ? "--camera-info-topic" : "--image-topic",
                     "only for a ROS bag (--dataset FILE.bag)");
  }
  if (args.device.empty()) {
    std::unique_ptr<FrameSource> recorded;
    if (bag) {
      recorded = OpenBagSource(args.dataset, {args.image_topic, args.camera_info_topic, args.camera});
    } else {
      DatasetOptions dataset_options;
      dataset_options.camera_path = args.camera;
      dataset_options.rate_hz = args.rate_hz;
      recorded = OpenFrameSource(args.dataset, dataset_options);
    }
    if (!args.realtime) return std::make_unique<ReadAheadSource>(std::move(recorded));
    PacedSourceOptions paced;
    paced.stop = &g_stop_requested;
    return std::make_unique<PacedSource>(std::move(recorded), paced);
  }
  if (args.camera.empty()) {
    throw InputError("--device", "a live camera needs a camera calibration file (--camera)");
  }
  CameraSourceOptions camera_options;
  camera_options.stop = &g_stop_requested;
  // V4L2 for device paths and camera indices; anything else (a stream URL) as OpenCV sees fit.
  const bool index = args.device.find_first_not_of("0123456789") == std::string::npos;
  camera_options.api = args.device.starts_with("/dev/") || index ? cv::CAP_V4L2 : cv::CAP_ANY;
  return std::make_unique<CameraSource>(args.device, ReadCameraModel(args.camera), camera_options);
}

// The options `run` starts from without flags or config file: what --print-config writes.
SystemOptions RunDefaults() {
  return DefaultRunOptions(/*blocking=*/false, /*vocabulary=*/nullptr, /*loop_closing=*/true);
}

// Run's defaults < the config file < the flags given that set options. Data (marker map,
// vocabulary) come later.
SystemOptions RunOptions(const RunArgs& args) {
  if (args.num_features_given && args.num_features < 100) {
    throw InputError("--features",
                     "expected at least 100, got " + std::to_string(args.num_features));
  }
  if (args.marker_size_given && !(args.marker_size_m >= 0.0)) {
    throw InputError("--marker-size",
                     "expected a side >= 0 m, got " + std::to_string(args.marker_size_m));
  }
  SystemOptions options = RunDefaults();
  if (!args.config.empty()) ReadSystemOptions(args.config, options);
  if (args.blocking) options.blocking = true;
  if (args.no_loop_closing) options.places.loop_closing = false;
  if (args.num_features_given) options.extractor.num_features = args.num_features;
  if (args.marker_size_given) options.marker_mapping.unknown_marker_size_m = args.marker_size_m;
  if (args.ground_vehicle && !options.marker_mapping.ground_plane_prior) {
    options.marker_mapping.ground_plane_prior = GroundPlanePriorOptions{};
  }
  return options;
}

int RunSlam(const RunArgs& args) {
  SystemOptions options = RunOptions(args);
  if (args.print_config) {
    std::fputs(SystemOptionsYaml(options).c_str(), stdout);
    return kExitOk;
  }
  if (args.out.empty()) throw InputError("--out", "missing: the output folder is required");
  if (args.rate_hz < 0.0) throw InputError("--rate", "expected a rate >= 0 Hz");
  CheckMapArgs(args);
  if (std::filesystem::exists(args.out) && !std::filesystem::is_directory(args.out)) {
    throw InputError(args.out, "exists and is not a directory");
  }
  const StopOnInterrupt stop_on_interrupt;
  const std::unique_ptr<FrameSource> source = OpenSource(args);
  std::optional<std::filesystem::path> markers_path = source->markers_path();
  if (!args.markers.empty()) markers_path = args.markers;
  if (args.no_markers) markers_path.reset();
  if (options.marker_mapping.ground_plane_prior && !markers_path) {  // before the vocabulary
    throw InputError(args.ground_vehicle ? "--ground-vehicle"
                                         : args.config + ": marker_mapping.ground_plane_prior",
                     "needs markers: the plane is held in their world frame");
  }
  const std::filesystem::path vocabulary =
      args.vocabulary.empty() ? DefaultVocabularyPath() : std::filesystem::path(args.vocabulary);
  options.vocabulary = std::make_shared<const Vocabulary>(Vocabulary::Load(vocabulary));
  if (markers_path) {
    options.marker_map = ReadMarkerMapJson(*markers_path);
    options.detector.dictionary = options.marker_map->dictionary;
  }
  const bool markers = options.marker_map.has_value();
  MapReuse reuse;
  if (!args.load_map.empty()) LoadMapForRun(args.load_map, source->camera(), reuse);
  reuse.localize_only = args.localize_only;
  reuse.save = args.save_map;
  RunControl control;
  control.max_frames = args.max_frames;
  control.stop = &g_stop_requested;
  const SlamRunResult result =
      RunSlamOnSource(*source, args.device.empty() ? args.dataset : args.device, options, markers,
                      args.out, !args.quiet, std::move(reuse), control);
  std::printf("%s\n", SlamRunSummary(result, args.out).c_str());
  if (!args.save_map.empty()) {
    std::printf("map saved to %s (%d keyframes, %d points)\n", args.save_map.c_str(),
                result.stats.keyframes, result.stats.map_points);
  }
  return kExitOk;
}

}  // namespace

void AddRunCommand(CLI::App& app, int& exit_status) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* run =
      app.add_subcommand("run",
                         "SLAM on a sequence -> trajectory.tum, keyframes.tum, map.ply, stats.json "
                         "(+ markers.json with a marker map)");
  CLI::Option* dataset =
      run->add_option("--dataset", args->dataset,
                      "the sequence: EuRoC layout (mav0/cam0), TUM RGB-D folder, KITTI odometry "
                      "folder (image_0/, calib.txt, times.txt), image folder, video file or "
                      "ROS 1 bag (FILE.bag, with --image-topic)");
  CLI::Option* device = run->add_option(
      "--device", args->device,
      "a live camera instead of --dataset: /dev/videoN (V4L2) or a camera index; needs "
      "--camera; Ctrl-C ends the run and writes its outputs; frames the SLAM has no time for "
      "are dropped (stats.json frames.dropped)");
  dataset->excludes(device);
  device->excludes(dataset);
  run->add_flag("--realtime", args->realtime,
                "replay --dataset at its recorded rate, as the camera delivered it: frames the "
                "SLAM has no time for are dropped (stats.json frames.dropped), as with --device")
      ->excludes(device);
  run->add_option("--image-topic", args->image_topic,
                  "ROS bag: the image topic (sensor_msgs/Image or CompressedImage)");
  run->add_option("--camera-info-topic", args->camera_info_topic,
                  "ROS bag: the sensor_msgs/CameraInfo topic (default: the image topic's "
                  "namespace + /camera_info; --camera replaces it)");
  run->add_option("--max-frames", args->max_frames, "stop after this many frames (0: all)")
      ->capture_default_str();
  run->add_option("--out", args->out,
                  "output folder, required (replaced only when the run succeeds)");
  run->add_option("--config", args->config,
                  "options file (YAML, as --print-config writes it; keys left out keep their "
                  "defaults); --blocking, --features, --marker-size, --no-loop-closing and "
                  "--ground-vehicle override it");
  run->add_flag("--print-config", args->print_config,
                "write the options this run would use (defaults, --config, flags) as commented "
                "YAML to stdout and exit");
  run->add_option("--camera", args->camera,
                  "calibration file (EuRoC sensor.yaml, OpenCV YAML/XML, Kalibr camchain, ROS "
                  "camera_info or ORB-SLAM3 settings); required for TUM, image folders, videos "
                  "and live cameras, replaces the sequence's own for EuRoC, KITTI and bags");
  run->add_flag("--no-markers", args->no_markers,
                "ignore the sequence's markers.json (keypoints only). Without this flag a "
                "markers.json in the sequence puts the run in the marker world frame, with "
                "metric scale and marker relocalisation");
  run->add_flag("--ground-vehicle", args->ground_vehicle,
                "the camera rides a ground vehicle on a level floor (markers.json's world z up): "
                "the adjustment of the whole map holds every keyframe near one height and tilt, "
                "both estimated (needs markers)");
  run->add_option("--vocabulary", args->vocabulary,
                  "bag-of-words vocabulary for relocalisation and loop closing (default: " +
                      std::string(kDefaultVocabularyName) + " shipped with arucoslam)");
  run->add_flag("--no-loop-closing", args->no_loop_closing,
                "do not detect or close loops (relocalisation stays on)");
  run->add_option("--markers", args->markers,
                  "known markers (markers.json) to use instead of the sequence's; markers it "
                  "lacks are mapped online and written to markers.json (fixed: false)");
  const SystemOptions defaults = RunDefaults();
  args->marker_size_m = defaults.marker_mapping.unknown_marker_size_m;
  CLI::Option* marker_size =
      run->add_option("--marker-size", args->marker_size_m,
                      "side in metres of markers the marker map lacks (0: that of its first "
                      "marker); overrides the config file")
          ->capture_default_str();
  run->add_flag("--blocking", args->blocking,
                "track and map each frame in turn on one thread (deterministic)");
  run->add_flag("--quiet", args->quiet, "no progress line");
  args->num_features = defaults.extractor.num_features;
  CLI::Option* features = run->add_option("--features", args->num_features,
                                          "ORB features per image; overrides the config file")
                              ->capture_default_str();
  run->add_option("--rate", args->rate_hz,
                  "frame rate in Hz giving the timestamps of an image folder (0: from the "
                  "camera file) or a video (0: the container's timestamps)")
      ->capture_default_str();
  run->add_option("--save-map", args->save_map,
                  "write the map to this file after the run (binary, versioned)");
  run->add_option("--load-map", args->load_map,
                  "start from this map file instead of an empty map: frames get poses once "
                  "relocalised in it (markers or keyframe matches), no new map is started");
  run->add_flag("--localize-only", args->localize_only,
                "with --load-map: track against the loaded map without adding keyframes or "
                "points");
  run->callback([args, features, marker_size, &exit_status] {
    args->num_features_given = features->count() > 0;
    args->marker_size_given = marker_size->count() > 0;
    exit_status = RunSlam(*args);
  });
}

}  // namespace arucoslam
