// Trajectory files: a list of timestamped camera poses (world_from_cam) read from TUM,
// EuRoC ground-truth csv or KITTI files and written as TUM; plus a run's stats.json.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

// Poses in time order as they appear in the file; timestamps in seconds.
struct Trajectory {
  std::vector<double> timestamps;  // seconds
  std::vector<Rigid3> poses;       // world_from_cam, metres
  // The rotation blocks exactly as a KITTI file gives them (7 digits, not quite orthonormal);
  // empty for other formats. evo computes relative motions on these raw matrices, so the
  // translation errors use them to agree with it to the last digit.
  std::vector<Eigen::Matrix3d> raw_rotations;

  std::size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
  void Add(double timestamp, const Rigid3& pose) {
    timestamps.push_back(timestamp);
    poses.push_back(pose);
  }
  // Appends pose `index` of `other`, with its raw rotation when `other` has them.
  void AddFrom(const Trajectory& other, std::size_t index) {
    Add(other.timestamps[index], other.poses[index]);
    if (!other.raw_rotations.empty()) raw_rotations.push_back(other.raw_rotations[index]);
  }
  // The raw rotation of pose i when present, else the pose's rotation matrix.
  Eigen::Matrix3d RotationMatrix(std::size_t i) const {
    return raw_rotations.empty() ? poses[i].RotationMatrix() : raw_rotations[i];
  }
};

enum class TrajectoryFormat { kTum, kEuroc, kKitti };

// Parsers of file contents; `source` names the file in errors. Every error is an InputError
// "<source>: line N: <what>", also for NaN or infinite values and for timestamps that go
// back in time (repeated stamps are kept, as evo keeps them).
// TUM: "t tx ty tz qx qy qz qw" per line, '#' comments and blank lines skipped, separators
// space, tab or comma.
Trajectory ParseTumTrajectory(const std::string& text, const std::string& source);
// EuRoC ground truth: "t[ns], px, py, pz, qw, qx, qy, qz[, ignored ...]", '#' header.
Trajectory ParseEurocTrajectory(const std::string& text, const std::string& source);
// KITTI: 12 numbers per line (row-major 3x4 world_from_cam). Timestamps are taken from
// `times_text` (one per line, same count) when given, else the line index (0, 1, 2, ...).
Trajectory ParseKittiTrajectory(const std::string& text, const std::string& source,
                                const std::optional<std::string>& times_text = std::nullopt,
                                const std::string& times_source = "");

// File readers (throw InputError naming the file when it is missing).
Trajectory ReadTumTrajectory(const std::filesystem::path& path);
Trajectory ReadEurocTrajectory(const std::filesystem::path& path);
Trajectory ReadKittiTrajectory(
    const std::filesystem::path& path,
    const std::optional<std::filesystem::path>& times_path = std::nullopt);

// Guesses the format from the content: a line of 12 numbers is KITTI; a first data line
// whose timestamp is an integer above 1e15 with comma separators is EuRoC; else TUM.
TrajectoryFormat DetectTrajectoryFormat(const std::string& text);
// Reads any of the three formats (see DetectTrajectoryFormat). A KITTI file gets the
// times file `<stem>_times.txt` or `times.txt` beside it when one exists.
Trajectory ReadTrajectory(const std::filesystem::path& path);

// TUM text with full precision (17 significant digits), one pose per line.
std::string FormatTumTrajectory(const Trajectory& trajectory);
// Writes atomically (util/files.h).
void WriteTumTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);

// Tracking events of a SLAM run, read from its stats.json. Minimal schema (other keys are
// ignored): {"tracking": {"losses": N, "relocalisations": M}} with N, M >= 0 integers.
struct RunTrackingStats {
  int losses = 0;
  int relocalisations = 0;
};
RunTrackingStats ParseRunStats(const std::string& json_text, const std::string& source);
RunTrackingStats ReadRunStats(const std::filesystem::path& path);

}  // namespace arucoslam
