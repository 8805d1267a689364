// RunSlamOnSource: one SLAM run over a frame source (file sequence, video or live camera),
// shared by `run` and `experiments`: feeds every frame to the System, then writes trajectory.tum,
// online.tum (FrameReport::online_world_from_cam), keyframes.tum, map.ply and stats.json (and with a marker map markers.json: known + mapped
// markers) into an output folder (all-or-nothing); optionally starts from a saved map and saves the
// map after the run.
#pragma once

#include <atomic>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/io/frame_source.h"
#include "arucoslam/io/map_file.h"
#include "arucoslam/io/slam_output.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/pipeline/system.h"

namespace arucoslam {

// Map reuse for one run (`run --load-map/--save-map/--localize-only`).
struct MapReuse {
  std::optional<MapData> loaded;  // start from this map (LoadMapForRun)
  MapFileInfo loaded_info;
  bool localize_only = false;  // track against `loaded` without changing it
  std::filesystem::path save;  // empty: the map is not saved
};

// Reads a map file for a run on `camera`'s images; InputError naming the file when it is
// missing, bad, empty or made with another camera.
void LoadMapForRun(const std::filesystem::path& path, const CameraModel& camera, MapReuse& reuse);

struct SlamRunResult {
  Trajectory trajectory;  // every frame with a pose, world_from_cam
  Trajectory keyframes;
  SlamRunStats stats;
  SystemStats timing;
  std::vector<Eigen::Vector3d> map_points;  // as written to map.ply
};

// The System options every SLAM run of the tools starts from (`run`, `experiments`, the ROS
// node): blocking or threaded, the given vocabulary with loop closing on or off, and the
// extractor's FAST floor for bland walls (5, not the library's 7, which the pipeline tests
// measure with). `run --print-config` writes them (threaded, loop closing on).
SystemOptions DefaultRunOptions(bool blocking, std::shared_ptr<const Vocabulary> vocabulary,
                                bool loop_closing);

// When a run ends before its source does. Either way the outputs are written for the frames
// processed so far.
struct RunControl {
  std::size_t max_frames = 0;               // stop after this many frames; 0: no limit
  const std::atomic<bool>* stop = nullptr;  // stop once set (Ctrl-C); may be null
};

// `dataset_label` names the dataset in stats.json; `markers` says whether the run used the
// sequence's marker map. A progress line goes to stderr when `progress` is set.
SlamRunResult RunSlamOnSource(FrameSource& source, const std::string& dataset_label,
                              const SystemOptions& options, bool markers,
                              const std::filesystem::path& out_dir, bool progress,
                              MapReuse reuse = {}, const RunControl& control = {});
// The same over every frame of a file sequence.
SlamRunResult RunSlamOnDataset(const Dataset& dataset, const std::string& dataset_label,
                               const SystemOptions& options, bool markers,
                               const std::filesystem::path& out_dir, bool progress,
                               MapReuse reuse = {});

// One summary line of a finished run.
std::string SlamRunSummary(const SlamRunResult& result, const std::string& out_dir);

}  // namespace arucoslam
