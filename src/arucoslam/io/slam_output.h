// SLAM run outputs: trajectory.tum (every frame with a pose), keyframes.tum, map.ply (map
// points) and stats.json (timings, counts, peak memory), written into one output folder.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {

// What stats.json records about a run.
struct SlamRunStats {
  std::string dataset;  // the sequence's path
  std::string layout;   // FrameSource::layout(): euroc, tum, kitti, images, video, camera
  bool blocking = true;
  bool markers = false;  // whether a marker map was used
  int frames = 0;
  int frames_tracked = 0;  // frames with a pose
  int frames_lost = 0;
  int inconsistent_poses = 0;  // tracked, left out of the trajectory: off their keyframes
  int frames_dropped = 0;      // live camera: captured but never processed (the SLAM was busy)
  // With markers: frames without a pose that saw no marker either (nothing to locate them).
  int frames_unposed_without_markers = 0;
  bool interrupted = false;    // the run stopped early on request (Ctrl-C)
  int losses = 0;              // transitions tracking -> lost
  int relocalisations = 0;
  int loops_closed = 0;
  int global_bundle_adjustments = 0;  // applied after loop closures
  int initialization_attempts = 0;
  int initializations = 0;
  int resets = 0;
  int keyframes_inserted = 0;
  int keyframes = 0;                   // in the final map
  int map_points = 0;                  // in the final map
  int refined_frame_poses = 0;         // frames re-optimised against the final map
  int yielded_bundle_adjustments = 0;  // threaded: local BAs ended early for a waiting keyframe
  int radial_calibrations = 0;         // refinements of the camera's radial distortion applied
  double radial_k1_correction = 0.0;   // what they added to its k1
  // With a marker map: frames with a usable marker location, of which one ambiguous
  // marker settled by the motion prediction, and frames whose pose came from markers alone.
  int marker_fix_frames = 0;
  int marker_disambiguations = 0;
  int map_rotation_disambiguations = 0;  // ... of which by an unaligned map's voted orientation
  int covisible_disambiguations = 0;     // ... of which by unknown markers seen with it
  // At the end, with markers mapped: marker poses located again in the final marker map,
  // and frames without a pose located in it.
  int relocated_marker_poses = 0;
  int late_marker_poses = 0;
  int marker_only_poses = 0;
  // ... and how the map was fused with them: world alignments, pose-graph drift
  // corrections, bundle adjustments of a whole map with every marker view, closed maps
  // merged into a later one, and keypoint poses the markers rejected (a look-alike place).
  int world_alignments = 0;
  int marker_drift_corrections = 0;
  int marker_rejections = 0;
  int whole_map_marker_adjustments = 0;
  int map_merges = 0;
  double wall_time_s = 0.0;
  std::size_t peak_memory_bytes = 0;
  // Per-stage timings in milliseconds, e.g. {"tracking", summary}.
  std::vector<std::pair<std::string, TimingSummary>> timings_ms;
};

// ASCII PLY with one vertex (x y z, double) per point.
std::string FormatPlyPoints(const std::vector<Eigen::Vector3d>& points);
// stats.json text: {"format": "arucoslam.stats/1", "dataset", "layout", "interrupted",
// "frames": {..., "left_out", "dropped", with markers "unposed_without_markers"},
// "tracking": {"losses", "relocalisations", ...}, "map": {..., "loops_closed",
// "global_bundle_adjustments", "refined_frame_poses", "yielded_bundle_adjustments",
// "radial_calibrations", "radial_k1_correction"}, with markers
// "marker_locations":
// {"frames_with_fix", "disambiguated_by_motion", "disambiguated_by_map_rotation",
// "disambiguated_by_covisible_markers", "relocated_at_end", "posed_at_end",
// "marker_only_poses"}, "marker_fusion": {"world_alignments", "drift_corrections",
// "whole_map_adjustments", "map_merges", "rejected_keypoint_poses"},
// "timings_ms": {stage: {count, mean, median, p95, max}}, "wall_time_s", "peak_memory_bytes"}.
std::string FormatSlamStatsJson(const SlamRunStats& stats);

// Writes the four files into `dir` (which must exist), each atomically.
void WriteSlamOutput(const std::filesystem::path& dir, const Trajectory& trajectory,
                     const Trajectory& keyframes, const std::vector<Eigen::Vector3d>& points,
                     const SlamRunStats& stats);

}  // namespace arucoslam
