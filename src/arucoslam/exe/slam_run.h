// RunSlamOnDataset: one SLAM run over a whole sequence, shared by `run` and `experiments`:
// feeds every image to the System, then writes trajectory.tum, keyframes.tum, map.ply and
// stats.json (and with a marker map markers.json: known + mapped markers) into an output
// folder (all-or-nothing); optionally starts from a saved map and saves the map after the run.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/io/map_file.h"
#include "arucoslam/io/slam_output.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/pipeline/system.h"

namespace arucoslam {

// Map reuse for one run (`run --load-map/--save-map/--localize-only`).
struct MapReuse {
  std::optional<MapData> loaded;  // start from this map (LoadMapForRun)
  MapFileInfo loaded_info;
  bool localize_only = false;     // track against `loaded` without changing it
  std::filesystem::path save;     // empty: the map is not saved
};

// Reads a map file for a run on `camera`'s images; InputError naming the file when it is
// missing, bad, empty or made with another camera.
void LoadMapForRun(const std::filesystem::path& path, const CameraModel& camera,
                   MapReuse& reuse);

struct SlamRunResult {
  Trajectory trajectory;  // every frame with a pose, world_from_cam
  Trajectory keyframes;
  SlamRunStats stats;
  SystemStats timing;
  std::vector<Eigen::Vector3d> map_points;  // as written to map.ply
};

// The System options every SLAM run of the tools starts from (`run`, `experiments`): blocking
// or threaded, the given vocabulary with loop closing on or off, and the extractor's FAST floor
// for bland walls.
SystemOptions DefaultRunOptions(bool blocking, std::shared_ptr<const Vocabulary> vocabulary,
                                bool loop_closing);

// The frames a run reads, from a Dataset or another source (a ROS 1 bag, exe/bag_feed.h).
struct FrameFeed {
  std::string layout;  // stats.json's "layout"
  CameraModel camera;
  std::size_t size = 0;
  std::function<double(std::size_t)> timestamp_s;   // increasing
  std::function<cv::Mat(std::size_t)> load_image;  // 8-bit grey; may throw InputError
};

// The frames of `dataset`, which must outlive the feed.
FrameFeed DatasetFeed(const Dataset& dataset);

// `dataset_label` names the dataset in stats.json; `markers` says whether the run used the
// sequence's marker map. A progress line goes to stderr when `progress` is set.
SlamRunResult RunSlamOnFrames(const FrameFeed& frames, const std::string& dataset_label,
                              const SystemOptions& options, bool markers,
                              const std::filesystem::path& out_dir, bool progress,
                              MapReuse reuse = {});
// RunSlamOnFrames on DatasetFeed(dataset).
SlamRunResult RunSlamOnDataset(const Dataset& dataset, const std::string& dataset_label,
                               const SystemOptions& options, bool markers,
                               const std::filesystem::path& out_dir, bool progress,
                               MapReuse reuse = {});

// One summary line of a finished run.
std::string SlamRunSummary(const SlamRunResult& result, const std::string& out_dir);

}  // namespace arucoslam
