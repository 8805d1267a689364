#include "arucoslam/io/trajectory_io.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

struct NumberLine {
  int line_number = 0;  // 1-based
  std::vector<double> values;
  std::vector<std::string> tokens;
};

bool IsSeparator(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; }

// Splits `text` into lines of numbers, skipping blank lines and '#' comments. Throws
// InputError "<source>: line N: ..." for a token that is not a number.
std::vector<NumberLine> SplitNumberLines(const std::string& text, const std::string& source) {
  std::vector<NumberLine> lines;
  std::istringstream stream(text);
  std::string line;
  int line_number = 0;
  while (std::getline(stream, line)) {
    ++line_number;
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    NumberLine parsed;
    parsed.line_number = line_number;
    std::size_t pos = first;
    while (pos < line.size()) {
      while (pos < line.size() && IsSeparator(line[pos])) ++pos;
      if (pos >= line.size()) break;
      std::size_t end = pos;
      while (end < line.size() && !IsSeparator(line[end])) ++end;
      const std::string token = line.substr(pos, end - pos);
      const char* begin = token.data();
      if (!token.empty() && token[0] == '+') ++begin;
      double value = 0.0;
      const auto result = std::from_chars(begin, token.data() + token.size(), value);
      if (result.ec != std::errc() || result.ptr != token.data() + token.size()) {
        throw InputError(source, fmt::format("line {}: '{}' is not a number", line_number, token));
      }
      if (!std::isfinite(value)) {
        throw InputError(source,
                         fmt::format("line {}: value '{}' is not finite", line_number, token));
      }
      parsed.values.push_back(value);
      parsed.tokens.push_back(token);
      pos = end;
    }
    lines.push_back(std::move(parsed));
  }
  return lines;
}

void RequireCount(const NumberLine& line, std::size_t expected, bool at_least,
                  const std::string& source, const char* format_name) {
  const bool ok = at_least ? line.values.size() >= expected : line.values.size() == expected;
  if (!ok) {
    throw InputError(source, fmt::format("line {}: expected {}{} numbers ({}), found {}",
                                         line.line_number, at_least ? "at least " : "", expected,
                                         format_name, line.values.size()));
  }
}

Eigen::Quaterniond CheckedQuaternion(double w, double x, double y, double z, int line_number,
                                     const std::string& source) {
  const Eigen::Quaterniond q(w, x, y, z);
  const double norm = q.norm();
  if (norm < 0.5 || norm > 1.5) {
    throw InputError(
        source, fmt::format("line {}: quaternion norm {:.6g} is far from 1", line_number, norm));
  }
  return q;
}

void AddChecked(Trajectory& trajectory, double timestamp, const Rigid3& pose, int line_number,
                const std::string& source) {
  // Repeated stamps occur in real files (evo accepts them); going back in time does not.
  if (!trajectory.empty() && timestamp < trajectory.timestamps.back()) {
    throw InputError(source, fmt::format("line {}: timestamp {:.9f} goes back in time "
                                         "(previous {:.9f})",
                                         line_number, timestamp, trajectory.timestamps.back()));
  }
  trajectory.Add(timestamp, pose);
}

void RequireNotEmpty(const Trajectory& trajectory, const std::string& source) {
  if (trajectory.empty()) throw InputError(source, "no poses in the file");
}

}  // namespace

Trajectory ParseTumTrajectory(const std::string& text, const std::string& source) {
  Trajectory trajectory;
  for (const NumberLine& line : SplitNumberLines(text, source)) {
    RequireCount(line, 8, false, source, "TUM: t tx ty tz qx qy qz qw");
    const std::vector<double>& v = line.values;
    const Eigen::Quaterniond q =
        CheckedQuaternion(v[7], v[4], v[5], v[6], line.line_number, source);
    AddChecked(trajectory, v[0], Rigid3(q, Eigen::Vector3d(v[1], v[2], v[3])), line.line_number,
               source);
  }
  RequireNotEmpty(trajectory, source);
  return trajectory;
}

Trajectory ParseEurocTrajectory(const std::string& text, const std::string& source) {
  Trajectory trajectory;
  for (const NumberLine& line : SplitNumberLines(text, source)) {
    RequireCount(line, 8, true, source, "EuRoC: t[ns] px py pz qw qx qy qz ...");
    const std::vector<double>& v = line.values;
    const Eigen::Quaterniond q =
        CheckedQuaternion(v[4], v[5], v[6], v[7], line.line_number, source);
    // Nanoseconds as a double, then seconds: the same rounding as evo's reader.
    AddChecked(trajectory, v[0] / 1e9, Rigid3(q, Eigen::Vector3d(v[1], v[2], v[3])),
               line.line_number, source);
  }
  RequireNotEmpty(trajectory, source);
  return trajectory;
}

Trajectory ParseKittiTrajectory(const std::string& text, const std::string& source,
                                const std::optional<std::string>& times_text,
                                const std::string& times_source) {
  const std::vector<NumberLine> lines = SplitNumberLines(text, source);
  std::vector<NumberLine> times;
  if (times_text) {
    times = SplitNumberLines(*times_text, times_source);
    if (times.size() != lines.size()) {
      throw InputError(times_source, fmt::format("{} timestamps for {} poses in {}", times.size(),
                                                 lines.size(), source));
    }
  }
  Trajectory trajectory;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const NumberLine& line = lines[i];
    RequireCount(line, 12, false, source, "KITTI: row-major 3x4 matrix");
    Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) matrix(r, c) = line.values[4 * r + c];
    }
    const double det = matrix.topLeftCorner<3, 3>().determinant();
    if (std::abs(det - 1.0) > 1e-2) {
      throw InputError(source, fmt::format("line {}: rotation block has determinant {:.6g} "
                                           "(expected 1)",
                                           line.line_number, det));
    }
    double timestamp = static_cast<double>(i);
    if (times_text) {
      RequireCount(times[i], 1, false, times_source, "one timestamp in seconds");
      timestamp = times[i].values[0];
    }
    AddChecked(trajectory, timestamp, Rigid3::FromMatrix(matrix),
               times_text ? times[i].line_number : line.line_number,
               times_text ? times_source : source);
    trajectory.raw_rotations.push_back(matrix.topLeftCorner<3, 3>());
  }
  RequireNotEmpty(trajectory, source);
  return trajectory;
}

Trajectory ReadTumTrajectory(const std::filesystem::path& path) {
  return ParseTumTrajectory(ReadTextFile(path), path.string());
}

Trajectory ReadEurocTrajectory(const std::filesystem::path& path) {
  return ParseEurocTrajectory(ReadTextFile(path), path.string());
}

Trajectory ReadKittiTrajectory(const std::filesystem::path& path,
                               const std::optional<std::filesystem::path>& times_path) {
  const std::string text = ReadTextFile(path);
  if (!times_path) return ParseKittiTrajectory(text, path.string());
  return ParseKittiTrajectory(text, path.string(), ReadTextFile(*times_path), times_path->string());
}

TrajectoryFormat DetectTrajectoryFormat(const std::string& text) {
  std::istringstream stream(text);
  std::string line;
  while (std::getline(stream, line)) {
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    int count = 0;
    bool in_token = false;
    for (char c : line) {
      const bool separator = IsSeparator(c);
      if (!separator && !in_token) ++count;
      in_token = !separator;
    }
    if (count == 12) return TrajectoryFormat::kKitti;
    const std::size_t comma = line.find(',');
    if (comma != std::string::npos) {
      const std::string head = line.substr(first, comma - first);
      const bool integer = head.find_first_not_of("0123456789") == std::string::npos;
      if (integer && head.size() >= 16) return TrajectoryFormat::kEuroc;
    }
    return TrajectoryFormat::kTum;
  }
  return TrajectoryFormat::kTum;
}

Trajectory ReadTrajectory(const std::filesystem::path& path) {
  const std::string text = ReadTextFile(path);
  switch (DetectTrajectoryFormat(text)) {
    case TrajectoryFormat::kEuroc:
      return ParseEurocTrajectory(text, path.string());
    case TrajectoryFormat::kKitti: {
      const std::filesystem::path folder = path.parent_path();
      for (const std::filesystem::path& candidate :
           {folder / (path.stem().string() + "_times.txt"), folder / "times.txt"}) {
        if (std::filesystem::is_regular_file(candidate)) {
          return ParseKittiTrajectory(text, path.string(), ReadTextFile(candidate),
                                      candidate.string());
        }
      }
      return ParseKittiTrajectory(text, path.string());
    }
    case TrajectoryFormat::kTum:
      break;
  }
  return ParseTumTrajectory(text, path.string());
}

std::string FormatTumTrajectory(const Trajectory& trajectory) {
  std::string out = "# timestamp tx ty tz qx qy qz qw\n";
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const Rigid3& pose = trajectory.poses[i];
    const Eigen::Quaterniond& q = pose.rotation;
    const Eigen::Vector3d& t = pose.translation;
    out += fmt::format("{:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g}\n",
                       trajectory.timestamps[i], t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  }
  return out;
}

void WriteTumTrajectory(const std::filesystem::path& path, const Trajectory& trajectory) {
  WriteTextFileAtomically(path, FormatTumTrajectory(trajectory));
}

RunTrackingStats ParseRunStats(const std::string& json_text, const std::string& source) {
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::parse_error& error) {
    throw InputError(source, std::string("not valid JSON: ") + error.what());
  }
  if (!root.is_object() || !root.contains("tracking") || !root["tracking"].is_object()) {
    throw InputError(source, "expected an object with a \"tracking\" object");
  }
  const nlohmann::json& tracking = root["tracking"];
  RunTrackingStats stats;
  const auto read_count = [&](const char* key, int& value) {
    if (!tracking.contains(key)) {
      throw InputError(source, fmt::format("tracking.{}: missing", key));
    }
    const nlohmann::json& node = tracking[key];
    if (!node.is_number_integer() || node.get<long long>() < 0) {
      throw InputError(source, fmt::format("tracking.{}: expected an integer >= 0", key));
    }
    value = node.get<int>();
  };
  read_count("losses", stats.losses);
  read_count("relocalisations", stats.relocalisations);
  return stats;
}

RunTrackingStats ReadRunStats(const std::filesystem::path& path) {
  return ParseRunStats(ReadTextFile(path), path.string());
}

}  // namespace arucoslam
