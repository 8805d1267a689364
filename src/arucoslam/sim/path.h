// Camera paths for the simulator: a taught route (PathSpec waypoints, rounded by arcs, with a
// speed profile) and its repeat run, sampled at camera rate as world_from_cam poses.
#pragma once

#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/io/path_json.h"

namespace arucoslam {

// One camera pose: world_from_cam in the DESIGN.md convention (camera x right, y down,
// z forward along the heading; world z up).
struct TimedPose {
  double time_s = 0.0;
  Rigid3 world_from_cam;
};

// Which drive along the route: the taught run follows the smoothed route exactly (plus
// vibration); the repeat run retraces it with a small, smooth, seeded lateral deviation.
enum class PathRun { kTeach, kRepeat };

// A point of the driven route on the floor, every `kRouteSampleSpacing` metres.
struct RouteSample {
  double distance_m = 0.0;  // arc length from the start
  double x = 0.0;
  double y = 0.0;
  double heading_rad = 0.0;  // direction of travel, counter-clockwise from world +x
  double curvature = 0.0;    // 1/m, positive turning left
  double speed_m_s = 0.0;    // speed profile (0 at start and end)
  double time_s = 0.0;       // when the robot is here
};
inline constexpr double kRouteSampleSpacing = 0.01;  // metres

// The smoothed route with its speed profile (straight segments joined by arcs).
// Throws InputError("path", ...) when PathSpecProblem(spec) is not empty.
std::vector<RouteSample> PlanRoute(const PathSpec& spec);

// Camera poses at options.camera_rate_hz from t = 0 to the end of the route (at rest).
std::vector<TimedPose> GenerateCameraPath(const PathSpec& spec, PathRun run);

// How the camera moves along a route: a ground robot at walking pace (the PathOptions
// defaults, 30 Hz) or a car (several m/s, 10 Hz: large motion between frames, as in driving).
enum class PathMotion { kRobot, kCar };
// "robot" or "car"; throws InputError(`source`, ...) for any other name.
PathMotion PathMotionFromName(const std::string& name, const std::string& source);
// `options` with the speed, acceleration, turn and camera-rate limits of `motion` (height,
// pitch, vibration, repeat deviation and seed kept).
PathOptions WithMotion(PathOptions options, PathMotion motion);

// Duration (s) and length (m) of the route, for summaries.
double RouteDuration(const std::vector<RouteSample>& route);
double RouteLength(const std::vector<RouteSample>& route);

}  // namespace arucoslam
