#include "arucoslam/sim/path.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

constexpr double kPi = std::numbers::pi;

// A piece of the rounded route: a straight line (curvature 0) or a circular arc.
struct Primitive {
  double start_distance = 0.0;
  double length = 0.0;
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  double start_heading = 0.0;
  double curvature = 0.0;  // signed, 1/m
};

struct RoutePoint {
  Eigen::Vector2d position;
  double heading = 0.0;
  double curvature = 0.0;
};

RoutePoint EvaluatePrimitive(const Primitive& primitive, double sigma) {
  RoutePoint point;
  point.curvature = primitive.curvature;
  const double h0 = primitive.start_heading;
  if (primitive.curvature == 0.0) {
    point.heading = h0;
    point.position = primitive.start + sigma * Eigen::Vector2d(std::cos(h0), std::sin(h0));
    return point;
  }
  const double radius = 1.0 / primitive.curvature;  // signed
  const double h = h0 + primitive.curvature * sigma;
  const Eigen::Vector2d centre =
      primitive.start + radius * Eigen::Vector2d(-std::sin(h0), std::cos(h0));
  point.heading = h;
  point.position = centre + radius * Eigen::Vector2d(std::sin(h), -std::cos(h));
  return point;
}

double WrapAngle(double angle) { return std::remainder(angle, 2.0 * kPi); }

// Straight segments between the waypoints, with each interior corner replaced by an arc
// tangent to both segments. A corner may use at most half of a segment it shares with
// another corner (all of it next to the start or end).
std::vector<Primitive> RoundCorners(const PathSpec& spec) {
  const auto& wps = spec.waypoints;
  const std::size_t n = wps.size();
  std::vector<Eigen::Vector2d> points(n);
  for (std::size_t i = 0; i < n; ++i) points[i] = Eigen::Vector2d(wps[i].x, wps[i].y);
  std::vector<double> lengths(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) lengths[i] = (points[i + 1] - points[i]).norm();
  std::vector<double> turn(n, 0.0), tangent(n, 0.0), radius(n, 0.0);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const Eigen::Vector2d in = points[i] - points[i - 1];
    const Eigen::Vector2d out = points[i + 1] - points[i];
    turn[i] = WrapAngle(std::atan2(out.y(), out.x()) - std::atan2(in.y(), in.x()));
    if (std::abs(turn[i]) < 1e-9) continue;
    const double wanted =
        wps[i].turn_radius_m > 0.0 ? wps[i].turn_radius_m : spec.options.turn_radius_m;
    const double half_tan = std::tan(std::abs(turn[i]) / 2.0);
    const double share_in = (i == 1) ? 1.0 : 0.5;
    const double share_out = (i + 2 == n) ? 1.0 : 0.5;
    tangent[i] = std::min({wanted * half_tan, share_in * lengths[i - 1], share_out * lengths[i]});
    radius[i] = tangent[i] / half_tan;
  }
  std::vector<Primitive> primitives;
  double distance = 0.0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const Eigen::Vector2d direction = (points[i + 1] - points[i]) / lengths[i];
    const double heading = std::atan2(direction.y(), direction.x());
    Primitive line;
    line.start_distance = distance;
    line.start = points[i] + tangent[i] * direction;
    line.start_heading = heading;
    line.length = std::max(0.0, lengths[i] - tangent[i] - tangent[i + 1]);
    if (line.length > 0.0) {
      primitives.push_back(line);
      distance += line.length;
    }
    const std::size_t corner = i + 1;
    if (corner + 1 < n && tangent[corner] > 0.0) {
      Primitive arc;
      arc.start_distance = distance;
      arc.start = points[corner] - tangent[corner] * direction;
      arc.start_heading = heading;
      arc.curvature = (turn[corner] > 0.0 ? 1.0 : -1.0) / radius[corner];
      arc.length = radius[corner] * std::abs(turn[corner]);
      primitives.push_back(arc);
      distance += arc.length;
    }
  }
  return primitives;
}

RoutePoint EvaluateRoute(const std::vector<Primitive>& primitives, double distance) {
  auto it = std::upper_bound(primitives.begin(), primitives.end(), distance,
                             [](double d, const Primitive& p) { return d < p.start_distance; });
  const Primitive& primitive = (it == primitives.begin()) ? primitives.front() : *(it - 1);
  const double sigma = std::clamp(distance - primitive.start_distance, 0.0, primitive.length);
  return EvaluatePrimitive(primitive, sigma);
}

double TotalLength(const std::vector<Primitive>& primitives) {
  return primitives.back().start_distance + primitives.back().length;
}

// Speed limit from the turn and the forward/backward acceleration passes; then the time
// at each sample (trapezoidal in distance, exact for piecewise constant acceleration).
void AssignSpeedAndTime(const PathOptions& options, std::vector<RouteSample>& route) {
  const std::size_t n = route.size();
  for (RouteSample& sample : route) {
    const double k = std::abs(sample.curvature);
    double limit = options.max_speed_m_s;
    if (k > 0.0) {
      limit = std::min({limit, std::sqrt(options.max_lateral_acceleration_m_s2 / k),
                        options.max_yaw_rate_rad_s / k});
    }
    sample.speed_m_s = limit;
  }
  route.front().speed_m_s = 0.0;
  route.back().speed_m_s = 0.0;
  const double a2 = 2.0 * options.max_acceleration_m_s2;
  for (std::size_t i = 1; i < n; ++i) {
    const double ds = route[i].distance_m - route[i - 1].distance_m;
    route[i].speed_m_s = std::min(
        route[i].speed_m_s, std::sqrt(route[i - 1].speed_m_s * route[i - 1].speed_m_s + a2 * ds));
  }
  for (std::size_t i = n - 1; i-- > 0;) {
    const double ds = route[i + 1].distance_m - route[i].distance_m;
    route[i].speed_m_s = std::min(
        route[i].speed_m_s, std::sqrt(route[i + 1].speed_m_s * route[i + 1].speed_m_s + a2 * ds));
  }
  route.front().time_s = 0.0;
  for (std::size_t i = 1; i < n; ++i) {
    const double ds = route[i].distance_m - route[i - 1].distance_m;
    const double mean_speed = 0.5 * (route[i].speed_m_s + route[i - 1].speed_m_s);
    route[i].time_s = route[i - 1].time_s + (mean_speed > 0.0 ? ds / mean_speed : 0.0);
  }
}

// Small deterministic random numbers (the standard distributions are not portable).
class SplitMix {
 public:
  explicit SplitMix(std::uint64_t seed) : state_(seed) {}
  double Uniform() {  // [0, 1)
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53;
  }

 private:
  std::uint64_t state_;
};

// A smooth signal: three sines with seeded phases; amplitude <= 1.
struct SineSum {
  std::array<double, 3> weight{0.5, 0.3, 0.2};
  std::array<double, 3> frequency{};
  std::array<double, 3> phase{};

  SineSum(SplitMix& random, double base_frequency) {
    const std::array<double, 3> ratios{1.0, 0.61, 0.37};
    for (int k = 0; k < 3; ++k) {
      frequency[k] = base_frequency * ratios[k] * (0.9 + 0.2 * random.Uniform());
      phase[k] = 2.0 * kPi * random.Uniform();
    }
  }
  double Value(double x) const {
    double sum = 0.0;
    for (int k = 0; k < 3; ++k)
      sum += weight[k] * std::sin(2.0 * kPi * frequency[k] * x + phase[k]);
    return sum;
  }
  double Derivative(double x) const {
    double sum = 0.0;
    for (int k = 0; k < 3; ++k) {
      sum +=
          weight[k] * 2.0 * kPi * frequency[k] * std::cos(2.0 * kPi * frequency[k] * x + phase[k]);
    }
    return sum;
  }
};

// 0 at the ends of [0, length], 1 beyond `ramp` from them, smooth (C1) in between.
void Taper(double distance, double length, double ramp, double* value, double* derivative) {
  auto smooth = [ramp](double u, double* v, double* dv) {
    if (u >= ramp) {
      *v = 1.0;
      *dv = 0.0;
      return;
    }
    const double x = std::max(0.0, u) / ramp;
    *v = x * x * (3.0 - 2.0 * x);
    *dv = (u <= 0.0) ? 0.0 : 6.0 * x * (1.0 - x) / ramp;
  };
  double v0, d0, v1, d1;
  smooth(distance, &v0, &d0);
  smooth(length - distance, &v1, &d1);
  *value = v0 * v1;
  *derivative = d0 * v1 - v0 * d1;
}

Eigen::Quaterniond CameraRotation(double heading, double pitch, double roll) {
  Eigen::Matrix3d base;  // columns: camera x, y, z in the world for heading 0 (+x)
  base << 0, 0, 1,       //
      -1, 0, 0,          //
      0, -1, 0;
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond twist(Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()));
  return (yaw * Eigen::Quaterniond(base) * tilt * twist).normalized();
}

}  // namespace

std::vector<RouteSample> PlanRoute(const PathSpec& spec) {
  const std::string problem = PathSpecProblem(spec);
  if (!problem.empty()) throw InputError("path", problem);
  const std::vector<Primitive> primitives = RoundCorners(spec);
  const double length = TotalLength(primitives);
  const auto count = static_cast<std::size_t>(std::ceil(length / kRouteSampleSpacing - 1e-9));
  std::vector<RouteSample> route(count + 1);
  for (std::size_t i = 0; i <= count; ++i) {
    const double distance = std::min(length, static_cast<double>(i) * kRouteSampleSpacing);
    const RoutePoint point = EvaluateRoute(primitives, distance);
    route[i].distance_m = distance;
    route[i].x = point.position.x();
    route[i].y = point.position.y();
    route[i].heading_rad = point.heading;
    route[i].curvature = point.curvature;
  }
  AssignSpeedAndTime(spec.options, route);
  return route;
}

std::vector<TimedPose> GenerateCameraPath(const PathSpec& spec, PathRun run) {
  const PathOptions& options = spec.options;
  const std::vector<RouteSample> route = PlanRoute(spec);
  const std::vector<Primitive> primitives = RoundCorners(spec);
  const double length = route.back().distance_m;
  const double duration = route.back().time_s;

  // Teach and repeat vibrate differently; only the repeat run deviates sideways.
  const std::uint64_t salt = run == PathRun::kTeach ? 0x7EAC4ull : 0x4E9EA7ull;
  SplitMix random((static_cast<std::uint64_t>(options.seed) << 20) ^ salt);
  const SineSum pitch_signal(random, options.vibration_frequency_hz);
  const SineSum roll_signal(random, options.vibration_frequency_hz * 1.3);
  const SineSum lateral_signal(random, 1.0 / options.repeat_deviation_wavelength_m);
  const double deviation = run == PathRun::kRepeat ? options.repeat_deviation_m : 0.0;
  const double ramp = std::min(2.0, 0.25 * length);

  std::vector<TimedPose> poses;
  const auto frames =
      static_cast<std::size_t>(std::floor(duration * options.camera_rate_hz + 1e-9));
  poses.reserve(frames + 1);
  std::size_t index = 0;
  for (std::size_t frame = 0; frame <= frames; ++frame) {
    const double time = static_cast<double>(frame) / options.camera_rate_hz;
    while (index + 2 < route.size() && route[index + 1].time_s <= time) ++index;
    const RouteSample& a = route[index];
    const RouteSample& b = route[index + 1];
    const double span = b.time_s - a.time_s;
    const double u = span > 0.0 ? std::clamp((time - a.time_s) / span, 0.0, 1.0) : 0.0;
    const double distance = a.distance_m + u * (b.distance_m - a.distance_m);
    const double speed = a.speed_m_s + u * (b.speed_m_s - a.speed_m_s);
    const RoutePoint point = EvaluateRoute(primitives, distance);

    // Lateral offset d(s) along the left normal; the heading follows the offset path:
    // d(p + d n)/ds = t (1 - k d) + n d'.
    double taper = 0.0, taper_rate = 0.0;
    Taper(distance, length, ramp, &taper, &taper_rate);
    const double offset = deviation * taper * lateral_signal.Value(distance);
    const double offset_rate = deviation * (taper_rate * lateral_signal.Value(distance) +
                                            taper * lateral_signal.Derivative(distance));
    const Eigen::Vector2d normal(-std::sin(point.heading), std::cos(point.heading));
    const Eigen::Vector2d position = point.position + offset * normal;
    const double heading = point.heading + std::atan2(offset_rate, 1.0 - point.curvature * offset);

    // Vibration grows with speed (none at rest).
    const double shake = options.vibration_rad * std::min(1.0, speed / 0.5);
    const double pitch = options.camera_pitch_rad + shake * pitch_signal.Value(time);
    const double roll = shake * roll_signal.Value(time);
    TimedPose pose;
    pose.time_s = time;
    pose.world_from_cam =
        Rigid3(CameraRotation(heading, pitch, roll),
               Eigen::Vector3d(position.x(), position.y(), options.camera_height_m));
    poses.push_back(pose);
  }
  return poses;
}

PathMotion PathMotionFromName(const std::string& name, const std::string& source) {
  if (name == "robot") return PathMotion::kRobot;
  if (name == "car") return PathMotion::kCar;
  throw InputError(source, "expected robot or car, found '" + name + "'");
}

PathOptions WithMotion(PathOptions options, PathMotion motion) {
  const PathOptions robot;
  if (motion == PathMotion::kRobot) {
    options.turn_radius_m = robot.turn_radius_m;
    options.max_speed_m_s = robot.max_speed_m_s;
    options.max_acceleration_m_s2 = robot.max_acceleration_m_s2;
    options.max_lateral_acceleration_m_s2 = robot.max_lateral_acceleration_m_s2;
    options.max_yaw_rate_rad_s = robot.max_yaw_rate_rad_s;
    options.camera_rate_hz = robot.camera_rate_hz;
    return options;
  }
  // Town driving as in KITTI's odometry sequences: up to 6 m/s, 0.6 m between frames at
  // 10 Hz, turns at up to 3.4 degrees per frame.
  options.turn_radius_m = 3.0;
  options.max_speed_m_s = 6.0;
  options.max_acceleration_m_s2 = 2.5;
  options.max_lateral_acceleration_m_s2 = 3.0;
  options.max_yaw_rate_rad_s = 0.6;
  options.camera_rate_hz = 10.0;
  return options;
}

double RouteDuration(const std::vector<RouteSample>& route) {
  return route.empty() ? 0.0 : route.back().time_s;
}
double RouteLength(const std::vector<RouteSample>& route) {
  return route.empty() ? 0.0 : route.back().distance_m;
}

}  // namespace arucoslam
