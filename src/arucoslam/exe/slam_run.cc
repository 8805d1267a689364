#include "arucoslam/exe/slam_run.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>

#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/io/read_ahead_source.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {
namespace {

Trajectory ToTrajectory(const std::vector<StampedPose>& poses) {
  Trajectory trajectory;
  for (const StampedPose& pose : poses) trajectory.Add(pose.timestamp_s, pose.world_from_cam);
  return trajectory;
}

SlamRunStats MakeStats(const std::string& dataset_label, const FrameSource& source,
                       const System& system, bool blocking, bool markers, double wall_time_s) {
  const SystemStats stats = system.Stats();
  SlamRunStats out;
  out.dataset = dataset_label;
  out.layout = source.layout();
  out.frames_dropped = static_cast<int>(source.frames_dropped());
  out.frames_unposed_without_markers = stats.num_unposed_without_markers;
  out.blocking = blocking;
  out.markers = markers;
  out.frames = stats.num_frames;
  out.frames_tracked = stats.num_tracked;
  out.frames_lost = stats.num_lost;
  out.inconsistent_poses = stats.num_inconsistent_poses;
  out.losses = stats.num_losses;
  // From the place database, marker poses and keyframe matches in a loaded map.
  out.relocalisations = stats.places.num_relocalizations + stats.num_marker_relocalizations +
                        stats.num_map_relocalizations;
  out.loops_closed = static_cast<int>(stats.places.loops.size());
  out.global_bundle_adjustments = stats.places.num_global_bundle_adjustments;
  out.initialization_attempts = stats.num_initialization_attempts;
  out.initializations = stats.num_initializations;
  out.resets = stats.map_session.num_resets;
  out.keyframes_inserted = stats.num_keyframes_inserted;
  out.keyframes = static_cast<int>(system.map().NumKeyframes());
  out.map_points = static_cast<int>(system.map().NumMapPoints());
  out.refined_frame_poses = stats.num_refined_frame_poses;
  out.yielded_bundle_adjustments = stats.num_yielded_bundle_adjustments;
  out.radial_calibrations = stats.num_radial_calibrations;
  out.radial_k1_correction = stats.radial_k1_correction;
  out.marker_fix_frames = stats.marker_fusion.num_located_frames;
  out.marker_disambiguations = stats.marker_fusion.num_disambiguations;
  out.map_rotation_disambiguations = stats.marker_fusion.num_map_rotation_disambiguations;
  out.covisible_disambiguations = stats.marker_fusion.num_covisible_disambiguations;
  out.relocated_marker_poses = stats.num_relocated_marker_poses;
  out.late_marker_poses = stats.num_late_marker_poses;
  out.marker_only_poses = stats.num_marker_only_poses;
  out.world_alignments = stats.world_anchoring.num_alignments;
  out.marker_drift_corrections = stats.world_anchoring.num_drift_corrections;
  out.marker_rejections = stats.marker_fusion.num_rejected_poses;
  out.whole_map_marker_adjustments = stats.num_whole_map_marker_adjustments;
  out.map_merges = stats.map_session.num_map_merges;
  out.wall_time_s = wall_time_s;
  out.peak_memory_bytes = PeakMemoryBytes();
  out.timings_ms = {{"extraction", stats.extraction_ms.Summarize()},
                    {"tracking", stats.tracking_ms.Summarize()},
                    {"frame", stats.frame_ms.Summarize()},
                    {"local_mapping", stats.local_mapping_ms.Summarize()},
                    {"triangulation", stats.triangulation_ms.Summarize()},
                    {"fusion", stats.fusion_ms.Summarize()},
                    {"local_bundle_adjustment", stats.local_bundle_adjustment_ms.Summarize()},
                    {"culling", stats.culling_ms.Summarize()}};
  if (stats.places.loop_detection_ms.Count() > 0 || stats.places.num_relocalization_attempts > 0) {
    out.timings_ms.push_back({"relocalisation", stats.places.relocalization_ms.Summarize()});
    out.timings_ms.push_back({"loop_detection", stats.places.loop_detection_ms.Summarize()});
    out.timings_ms.push_back({"loop_correction", stats.places.loop_correction_ms.Summarize()});
    out.timings_ms.push_back(
        {"global_bundle_adjustment", stats.places.global_bundle_adjustment_ms.Summarize()});
  }
  if (markers) {
    out.timings_ms.push_back({"markers", stats.marker_ms.Summarize()});
    out.timings_ms.push_back({"marker_wait", stats.marker_wait_ms.Summarize()});
  }
  return out;
}

}  // namespace

void LoadMapForRun(const std::filesystem::path& path, const CameraModel& camera, MapReuse& reuse) {
  MapData map = LoadMapFile(path, &reuse.loaded_info);
  if (map.NumKeyframes() == 0) throw InputError(path.string(), "the map has no keyframes");
  const CameraModel& mapped = map.keyframes().begin()->second.camera;
  if (mapped.width != camera.width || mapped.height != camera.height ||
      std::abs(mapped.fx - camera.fx) > 1e-6 * camera.fx ||
      std::abs(mapped.fy - camera.fy) > 1e-6 * camera.fy) {
    throw InputError(path.string(),
                     fmt::format("map made with a {}x{} camera (fx {:.1f}), the sequence's is "
                                 "{}x{} (fx {:.1f})",
                                 mapped.width, mapped.height, mapped.fx, camera.width,
                                 camera.height, camera.fx));
  }
  reuse.loaded = std::move(map);
}

SystemOptions DefaultRunOptions(bool blocking, std::shared_ptr<const Vocabulary> vocabulary,
                                bool loop_closing) {
  SystemOptions options;
  options.blocking = blocking;
  options.vocabulary = std::move(vocabulary);
  options.places.loop_closing = loop_closing;
  return options;
}

SlamRunResult RunSlamOnSource(FrameSource& source, const std::string& dataset_label,
                              const SystemOptions& options, bool markers,
                              const std::filesystem::path& out_dir, bool progress, MapReuse reuse,
                              const RunControl& control) {
  StagedDirectory staged(out_dir);
  const Stopwatch wall;
  SystemOptions run_options = options;
  // A camera's frames are dropped while tracking waits.
  run_options.live_source = options.live_source || source.live();
  System system(source.camera(), run_options);
  if (reuse.loaded) {
    system.StartFromMap(std::move(*reuse.loaded), reuse.loaded_info.world_aligned,
                        reuse.localize_only);
  }
  const auto stop_requested = [&control] {
    return control.stop != nullptr && control.stop->load();
  };
  std::optional<std::size_t> total = source.size();
  if (total && control.max_frames > 0) total = std::min(*total, control.max_frames);
  std::size_t processed = 0;
  bool interrupted = false;
  Trajectory online;  // each frame's pose as its FrameReport gave it
  while (control.max_frames == 0 || processed < control.max_frames) {
    if (stop_requested()) {
      interrupted = true;
      break;
    }
    std::optional<SourceFrame> frame = source.Next();
    if (!frame) {
      interrupted = stop_requested();  // a live source ends on the same request
      break;
    }
    const FrameReport report = system.ProcessImage(frame->image, frame->timestamp_s);
    ++processed;
    if (report.online_world_from_cam) online.Add(report.timestamp_s, *report.online_world_from_cam);
    if (progress && (processed % 10 == 1 || (total && processed == *total))) {
      std::fprintf(stderr, "\rframe %zu%s  %-15s keyframes %zu  points %zu", processed,
                   total ? fmt::format("/{}", *total).c_str() : "",
                   TrackingStateName(report.state).c_str(), system.map().NumKeyframes(),
                   system.map().NumMapPoints());
      std::fflush(stderr);
    }
  }
  system.Finish();
  if (progress) std::fprintf(stderr, "\n");
  SlamRunResult result;
  result.stats =
      MakeStats(dataset_label, source, system, options.blocking, markers, wall.ElapsedSeconds());
  result.stats.interrupted = interrupted;
  result.trajectory = ToTrajectory(system.Trajectory());
  result.keyframes = ToTrajectory(system.KeyframePoses());
  result.timing = system.Stats();
  result.map_points = system.MapPoints();
  WriteSlamOutput(staged.path(), result.trajectory, result.keyframes, result.map_points,
                  result.stats);
  WriteTumTrajectory(staged.path() / "online.tum", online);
  if (!reuse.save.empty()) {
    MapFileInfo info;
    info.world_aligned = system.world_aligned();
    SaveMapFile(system.map(), reuse.save, info);
  }
  if (options.marker_map) {
    WriteMarkerMapJson(system.MarkerMapOutput(), staged.path() / "markers.json");
  }
  staged.Commit();
  return result;
}

SlamRunResult RunSlamOnDataset(const Dataset& dataset, const std::string& dataset_label,
                               const SystemOptions& options, bool markers,
                               const std::filesystem::path& out_dir, bool progress,
                               MapReuse reuse) {
  ReadAheadSource source(std::make_unique<DatasetSource>(dataset));
  return RunSlamOnSource(source, dataset_label, options, markers, out_dir, progress,
                         std::move(reuse));
}

std::string SlamRunSummary(const SlamRunResult& result, const std::string& out_dir) {
  const SlamRunStats& stats = result.stats;
  std::string line = fmt::format(
      "{} frames, {} tracked ({:.1f}%), {} losses, {} keyframes, {} points; tracking median "
      "{:.1f} ms, local mapping median {:.1f} ms; {:.1f} s -> {}",
      stats.frames, stats.frames_tracked,
      stats.frames > 0 ? 100.0 * stats.frames_tracked / stats.frames : 0.0, stats.losses,
      stats.keyframes, stats.map_points, result.timing.tracking_ms.Summarize().median,
      result.timing.local_mapping_ms.Summarize().median, stats.wall_time_s, out_dir);
  if (stats.frames_dropped > 0) {
    line += fmt::format("; {} frames dropped (the SLAM was busy)", stats.frames_dropped);
  }
  if (stats.interrupted) line += "; stopped early on request";
  if (stats.initializations == 0 && stats.keyframes == 0) {
    line += "\nmap not initialised (no camera motion found)";
  }
  return line;
}

}  // namespace arucoslam
