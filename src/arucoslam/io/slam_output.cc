#include "arucoslam/io/slam_output.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "arucoslam/util/files.h"

namespace arucoslam {

std::string FormatPlyPoints(const std::vector<Eigen::Vector3d>& points) {
  std::string text = fmt::format(
      "ply\nformat ascii 1.0\ncomment arucoslam map points (world frame, metres)\n"
      "element vertex {}\nproperty double x\nproperty double y\nproperty double z\n"
      "end_header\n",
      points.size());
  for (const Eigen::Vector3d& p : points) {
    text += fmt::format("{:.9g} {:.9g} {:.9g}\n", p.x(), p.y(), p.z());
  }
  return text;
}

std::string FormatSlamStatsJson(const SlamRunStats& stats) {
  nlohmann::ordered_json json;
  json["format"] = "arucoslam.stats/1";
  json["dataset"] = stats.dataset;
  json["layout"] = stats.layout;
  json["blocking"] = stats.blocking;
  json["markers"] = stats.markers;
  json["interrupted"] = stats.interrupted;
  json["frames"] = {
      {"total", stats.frames},
      {"tracked", stats.frames_tracked},
      {"lost", stats.frames_lost},
      {"left_out", stats.inconsistent_poses},
      {"dropped", stats.frames_dropped},
      {"tracked_fraction",
       stats.frames > 0 ? static_cast<double>(stats.frames_tracked) / stats.frames : 0.0}};
  if (stats.markers) json["frames"]["unposed_without_markers"] = stats.frames_unposed_without_markers;
  json["tracking"] = {{"losses", stats.losses},
                      {"relocalisations", stats.relocalisations},
                      {"initialization_attempts", stats.initialization_attempts},
                      {"initializations", stats.initializations},
                      {"resets", stats.resets}};
  json["map"] = {{"keyframes", stats.keyframes},
                 {"keyframes_inserted", stats.keyframes_inserted},
                 {"points", stats.map_points},
                 {"loops_closed", stats.loops_closed},
                 {"global_bundle_adjustments", stats.global_bundle_adjustments},
                 {"refined_frame_poses", stats.refined_frame_poses},
                 {"yielded_bundle_adjustments", stats.yielded_bundle_adjustments},
                 {"radial_calibrations", stats.radial_calibrations},
                 {"radial_k1_correction", stats.radial_k1_correction}};
  if (stats.markers) {
    json["marker_locations"] = {
        {"frames_with_fix", stats.marker_fix_frames},
        {"disambiguated_by_motion", stats.marker_disambiguations},
        {"disambiguated_by_map_rotation", stats.map_rotation_disambiguations},
        {"disambiguated_by_covisible_markers", stats.covisible_disambiguations},
        {"relocated_at_end", stats.relocated_marker_poses},
        {"posed_at_end", stats.late_marker_poses},
        {"marker_only_poses", stats.marker_only_poses}};
    json["marker_fusion"] = {{"world_alignments", stats.world_alignments},
                             {"drift_corrections", stats.marker_drift_corrections},
                             {"whole_map_adjustments", stats.whole_map_marker_adjustments},
                             {"map_merges", stats.map_merges},
                             {"rejected_keypoint_poses", stats.marker_rejections}};
  }
  nlohmann::ordered_json timings = nlohmann::ordered_json::object();
  for (const auto& [stage, summary] : stats.timings_ms) {
    timings[stage] = {{"count", summary.count},
                      {"mean", summary.mean},
                      {"median", summary.median},
                      {"p95", summary.p95},
                      {"max", summary.max}};
  }
  json["timings_ms"] = timings;
  json["wall_time_s"] = stats.wall_time_s;
  json["peak_memory_bytes"] = stats.peak_memory_bytes;
  return json.dump(2) + "\n";
}

void WriteSlamOutput(const std::filesystem::path& dir, const Trajectory& trajectory,
                     const Trajectory& keyframes, const std::vector<Eigen::Vector3d>& points,
                     const SlamRunStats& stats) {
  WriteTumTrajectory(dir / "trajectory.tum", trajectory);
  WriteTumTrajectory(dir / "keyframes.tum", keyframes);
  WriteTextFileAtomically(dir / "map.ply", FormatPlyPoints(points));
  WriteTextFileAtomically(dir / "stats.json", FormatSlamStatsJson(stats));
}

}  // namespace arucoslam
