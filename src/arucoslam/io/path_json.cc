#include "arucoslam/io/path_json.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <utility>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

constexpr const char* kFormat = "arucoslam.path/1";
constexpr double kMinWaypointDistance = 0.05;  // metres
constexpr double kMaxTurnDegrees = 170.0;

using Json = nlohmann::json;

// Every PathOptions field with its key, a pointer to it and the accepted range (closed
// unless `open_low`), so reading, writing and checking share one table.
struct OptionField {
  const char* key;
  double PathOptions::*member;
  double low;
  double high;
  bool open_low;
};

const std::vector<OptionField>& OptionFields() {
  static const std::vector<OptionField> fields = {
      {"turn_radius_m", &PathOptions::turn_radius_m, 0.0, 1e3, true},
      {"max_speed_m_s", &PathOptions::max_speed_m_s, 0.0, 30.0, true},
      {"max_acceleration_m_s2", &PathOptions::max_acceleration_m_s2, 0.0, 10.0, true},
      {"max_lateral_acceleration_m_s2", &PathOptions::max_lateral_acceleration_m_s2, 0.0, 10.0,
       true},
      {"max_yaw_rate_rad_s", &PathOptions::max_yaw_rate_rad_s, 0.0, 10.0, true},
      {"camera_height_m", &PathOptions::camera_height_m, 0.3, 1.0, false},
      {"camera_pitch_rad", &PathOptions::camera_pitch_rad, -0.5, 0.5, false},
      {"camera_rate_hz", &PathOptions::camera_rate_hz, 0.0, 1e3, true},
      {"vibration_rad", &PathOptions::vibration_rad, 0.0, 0.1, false},
      {"vibration_frequency_hz", &PathOptions::vibration_frequency_hz, 0.0, 100.0, true},
      {"repeat_deviation_m", &PathOptions::repeat_deviation_m, 0.0, 1.0, false},
      {"repeat_deviation_wavelength_m", &PathOptions::repeat_deviation_wavelength_m, 0.0, 1e3,
       true},
  };
  return fields;
}

std::string RangeText(const OptionField& field) {
  return std::string(field.open_low ? "(" : "[") + Json(field.low).dump() + ", " +
         Json(field.high).dump() + "]";
}

bool InRange(const OptionField& field, double value) {
  if (!std::isfinite(value) || value > field.high) return false;
  return field.open_low ? value > field.low : value >= field.low;
}

double ReadNumber(const Json& value, const std::string& source, const std::string& field) {
  if (!value.is_number()) {
    throw InputError(source, field + ": expected a number, found " + value.dump());
  }
  return value.get<double>();
}

void RejectUnknownKeys(const Json& object, const std::set<std::string>& known,
                       const std::string& source, const std::string& where) {
  for (const auto& item : object.items()) {
    if (known.count(item.key()) == 0) {
      throw InputError(source, where + "unknown key '" + item.key() + "'");
    }
  }
}

PathWaypoint ReadWaypoint(const Json& value, const std::string& source, const std::string& where) {
  if (!value.is_object()) {
    throw InputError(source, where + ": expected an object {\"x\", \"y\"}, found " + value.dump());
  }
  RejectUnknownKeys(value, {"x", "y", "turn_radius_m"}, source, where + ": ");
  PathWaypoint waypoint;
  for (const char* key : {"x", "y"}) {
    if (!value.contains(key)) throw InputError(source, where + ": missing \"" + key + "\"");
  }
  waypoint.x = ReadNumber(value["x"], source, where + ".x");
  waypoint.y = ReadNumber(value["y"], source, where + ".y");
  if (value.contains("turn_radius_m")) {
    waypoint.turn_radius_m = ReadNumber(value["turn_radius_m"], source, where + ".turn_radius_m");
  }
  return waypoint;
}

PathOptions ReadOptions(const Json& value, const std::string& source) {
  if (!value.is_object()) throw InputError(source, "options: expected an object");
  PathOptions options;
  std::set<std::string> known = {"seed"};
  for (const OptionField& field : OptionFields()) known.insert(field.key);
  RejectUnknownKeys(value, known, source, "options: ");
  for (const OptionField& field : OptionFields()) {
    if (!value.contains(field.key)) continue;
    const std::string name = std::string("options.") + field.key;
    const double number = ReadNumber(value[field.key], source, name);
    if (!InRange(field, number)) {
      throw InputError(source,
                       name + ": " + Json(number).dump() + " is outside " + RangeText(field));
    }
    options.*field.member = number;
  }
  if (value.contains("seed")) {
    const Json& seed = value["seed"];
    if (!seed.is_number_unsigned() || seed.get<std::uint64_t>() > 0xFFFFFFFFull) {
      throw InputError(
          source, "options.seed: expected an integer in [0, 4294967295], found " + seed.dump());
    }
    options.seed = static_cast<std::uint32_t>(seed.get<std::uint64_t>());
  }
  return options;
}

}  // namespace

bool PathOptions::Check(std::string* why) const {
  OptionCheck check(why);
  for (const OptionField& field : OptionFields()) {
    check.Rule(InRange(field, this->*field.member), field.key, this->*field.member,
               fmt::format("in {}", RangeText(field)));
  }
  return check.ok();
}

std::string PathSpecProblem(const PathSpec& spec) {
  if (!spec.options.Check()) {
    for (const OptionField& field : OptionFields()) {
      if (!InRange(field, spec.options.*field.member)) {
        return std::string("options.") + field.key + ": " +
               Json(spec.options.*field.member).dump() + " is outside " + RangeText(field);
      }
    }
  }
  const auto& wps = spec.waypoints;
  if (wps.size() < 2)
    return "waypoints: at least 2 are needed, found " + std::to_string(wps.size());
  for (std::size_t i = 0; i < wps.size(); ++i) {
    const std::string where = "waypoints[" + std::to_string(i) + "]";
    if (!std::isfinite(wps[i].x) || !std::isfinite(wps[i].y)) return where + ": not a finite point";
    if (!std::isfinite(wps[i].turn_radius_m) || wps[i].turn_radius_m < 0.0) {
      return where + ".turn_radius_m: expected a radius >= 0 (0 = default)";
    }
    if (i == 0) continue;
    const Eigen::Vector2d in(wps[i].x - wps[i - 1].x, wps[i].y - wps[i - 1].y);
    if (in.norm() < kMinWaypointDistance) {
      return where + ": closer than " + Json(kMinWaypointDistance).dump() +
             " m to the previous waypoint";
    }
    if (i + 1 == wps.size()) continue;
    const Eigen::Vector2d out(wps[i + 1].x - wps[i].x, wps[i + 1].y - wps[i].y);
    const double cosine = in.dot(out) / (in.norm() * std::max(out.norm(), 1e-12));
    const double degrees = std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi;
    if (degrees > kMaxTurnDegrees) {
      return where + ": the route turns back by " + std::to_string(std::lround(degrees)) +
             " degrees; a U-turn needs two corners (two waypoints side by side)";
    }
  }
  return "";
}

PathSpec ParsePathJson(const std::string& text, const std::string& source) {
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::parse_error& error) {
    throw InputError(source, std::string("not valid JSON: ") + error.what());
  }
  if (!root.is_object()) throw InputError(source, "expected a JSON object at the top");
  RejectUnknownKeys(root, {"format", "frame", "waypoints", "options"}, source, "");
  if (!root.contains("format") || root["format"] != kFormat) {
    throw InputError(source, std::string("format: expected \"") + kFormat + "\"");
  }
  if (root.contains("frame") && root["frame"] != "world") {
    throw InputError(source, "frame: expected \"world\", found " + root["frame"].dump());
  }
  if (!root.contains("waypoints") || !root["waypoints"].is_array()) {
    throw InputError(source, "waypoints: expected an array of {\"x\", \"y\"} objects");
  }
  PathSpec spec;
  const Json& waypoints = root["waypoints"];
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    spec.waypoints.push_back(
        ReadWaypoint(waypoints[i], source, "waypoints[" + std::to_string(i) + "]"));
  }
  if (root.contains("options")) spec.options = ReadOptions(root["options"], source);
  const std::string problem = PathSpecProblem(spec);
  if (!problem.empty()) throw InputError(source, problem);
  return spec;
}

PathSpec ReadPathJson(const std::filesystem::path& path) {
  return ParsePathJson(ReadTextFile(path), path.string());
}

std::string PathJsonText(const PathSpec& spec) {
  Json root;
  root["format"] = kFormat;
  root["frame"] = "world";
  Json waypoints = Json::array();
  for (const PathWaypoint& waypoint : spec.waypoints) {
    Json item = {{"x", waypoint.x}, {"y", waypoint.y}};
    if (waypoint.turn_radius_m > 0.0) item["turn_radius_m"] = waypoint.turn_radius_m;
    waypoints.push_back(item);
  }
  root["waypoints"] = waypoints;
  Json options;
  for (const OptionField& field : OptionFields()) options[field.key] = spec.options.*field.member;
  options["seed"] = spec.options.seed;
  root["options"] = options;
  return root.dump(2) + "\n";
}

void WritePathJson(const std::filesystem::path& path, const PathSpec& spec) {
  WriteTextFileAtomically(path, PathJsonText(spec));
}

}  // namespace arucoslam
