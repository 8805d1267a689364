// PathSpec: a taught route as the user writes it (path.json): waypoints on the floor plus the
// options that turn them into camera poses (sim/path.h). ReadPathJson/WritePathJson do the file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace arucoslam {

// One waypoint of the route on the floor (world x, y in metres; world z is up).
struct PathWaypoint {
  double x = 0.0;
  double y = 0.0;
  // Radius of the arc that rounds the corner at this waypoint, metres; 0 = the route's
  // default (PathOptions::turn_radius_m). Shrunk automatically where segments are short.
  double turn_radius_m = 0.0;
};

// How waypoints become a drive and camera poses. Defaults: a ground robot at walking pace.
struct PathOptions {
  double turn_radius_m = 1.2;                  // default corner radius, metres (> 0)
  double max_speed_m_s = 1.0;                  // top speed on straights, m/s (0, 30]
  double max_acceleration_m_s2 = 0.5;          // along the path (start, stop, slow-downs), m/s^2
  double max_lateral_acceleration_m_s2 = 0.3;  // in turns: v^2 * curvature <= this, m/s^2
  double max_yaw_rate_rad_s = 0.7;             // in turns: v * curvature <= this, rad/s
  double camera_height_m = 0.6;                // optical centre above the floor, [0.3, 1.0] m
  double camera_pitch_rad = 0.0;               // fixed tilt, positive looks up, |.| <= 0.5 rad
  double camera_rate_hz = 30.0;                // pose sampling rate, Hz (> 0)
  double vibration_rad = 0.003;                // amplitude of pitch and roll vibration, rad (>= 0)
  double vibration_frequency_hz = 3.0;         // main vibration frequency, Hz (> 0)
  double repeat_deviation_m = 0.08;            // repeat run: lateral deviation amplitude, m (>= 0)
  double repeat_deviation_wavelength_m = 7.0;  // repeat run: shortest wavelength, m (> 0)
  std::uint32_t seed = 1;                      // vibration and repeat deviation come from it

  bool Check(std::string* why = nullptr) const;
};

// The content of path.json. A route that ends where it starts is a loop.
struct PathSpec {
  std::vector<PathWaypoint> waypoints;  // at least 2, consecutive ones >= 0.05 m apart
  PathOptions options;
};

// Why `spec` cannot be driven ("waypoint 3: ..."), or an empty string when it can.
std::string PathSpecProblem(const PathSpec& spec);

// Reads path.json (format "arucoslam.path/1"): {"format", "frame": "world", "waypoints":
// [{"x", "y", "turn_radius_m"?}...], "options": {any PathOptions field by name}?}.
// Missing options keep their defaults; unknown keys, wrong types, out-of-range values and
// undrivable routes are InputError naming the file and the field.
PathSpec ReadPathJson(const std::filesystem::path& path);
PathSpec ParsePathJson(const std::string& text, const std::string& source);

// Writes every field (atomically); ReadPathJson gives the same spec back exactly.
void WritePathJson(const std::filesystem::path& path, const PathSpec& spec);
std::string PathJsonText(const PathSpec& spec);

}  // namespace arucoslam
