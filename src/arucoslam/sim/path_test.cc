#include "arucoslam/sim/path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

constexpr double kPi = std::numbers::pi;

// A loop like the factory's: a long straight, a 90-degree corner, a U-turn made of two
// corners 3 m apart, and back to the start.
PathSpec LoopSpec() {
  PathSpec spec;
  spec.waypoints = {{0, 0}, {20, 0}, {20, 3}, {0, 3, 0.9}, {-3, 3, 0.9}, {-3, 0}, {0, 0}};
  // Corners: (20,0) left, (20,3) left, (0,3) straight on -> no arc, (-3,3) left, (-3,0) left.
  return spec;
}

double Heading(const Rigid3& world_from_cam) {
  const Eigen::Vector3d forward = world_from_cam.rotation * Eigen::Vector3d::UnitZ();
  return std::atan2(forward.y(), forward.x());
}

TEST(PathTest, SpeedStaysWithinLimitsAndSlowsInTurns) {
  const PathSpec spec = LoopSpec();
  const std::vector<RouteSample> route = PlanRoute(spec);
  double max_speed = 0.0, max_lateral = 0.0, min_turn_speed = 10.0;
  for (const RouteSample& sample : route) {
    max_speed = std::max(max_speed, sample.speed_m_s);
    max_lateral =
        std::max(max_lateral, sample.speed_m_s * sample.speed_m_s * std::abs(sample.curvature));
    if (std::abs(sample.curvature) > 0.5)
      min_turn_speed = std::min(min_turn_speed, sample.speed_m_s);
  }
  EXPECT_LE(max_speed, 1.0 + 1e-12);
  EXPECT_GT(max_speed, 0.99);  // reaches top speed on the 20 m straight
  EXPECT_LE(max_lateral, spec.options.max_lateral_acceleration_m_s2 + 1e-9);
  // In a 0.9 m turn: v <= sqrt(0.3 * 0.9) = 0.52 m/s.
  EXPECT_LE(min_turn_speed, std::sqrt(0.3 * 0.9) + 1e-9);

  // Camera poses: speed from finite differences never above the top speed.
  const std::vector<TimedPose> poses = GenerateCameraPath(spec, PathRun::kRepeat);
  double max_pose_speed = 0.0;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    const double dt = poses[i].time_s - poses[i - 1].time_s;
    EXPECT_NEAR(dt, 1.0 / 30.0, 1e-12);
    max_pose_speed = std::max(
        max_pose_speed,
        (poses[i].world_from_cam.translation - poses[i - 1].world_from_cam.translation).norm() /
            dt);
  }
  EXPECT_LE(max_pose_speed, 1.0 + 0.02);  // the repeat's weave adds at most ~1%
}

TEST(PathTest, CarMotionMovesFarBetweenFramesAtTenHertz) {
  PathSpec spec = LoopSpec();
  spec.options = WithMotion(spec.options, PathMotionFromName("car", "--motion"));
  const std::vector<TimedPose> poses = GenerateCameraPath(spec, PathRun::kTeach);
  ASSERT_GT(poses.size(), 10u);
  double max_step = 0.0, max_yaw_step = 0.0;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    EXPECT_NEAR(poses[i].time_s - poses[i - 1].time_s, 0.1, 1e-12);
    max_step = std::max(
        max_step,
        (poses[i].world_from_cam.translation - poses[i - 1].world_from_cam.translation).norm());
    double yaw = Heading(poses[i].world_from_cam) - Heading(poses[i - 1].world_from_cam);
    yaw = std::remainder(yaw, 2.0 * kPi);
    max_yaw_step = std::max(max_yaw_step, std::abs(yaw));
  }
  // Up to 6 m/s on the 20 m straight (reached after 7.2 m at 2.5 m/s^2): 0.6 m per frame.
  EXPECT_GT(max_step, 0.55);
  EXPECT_LE(max_step, 0.6 + 1e-9);
  // Turns at most 0.6 rad/s: 3.4 degrees per frame (vibration adds no yaw).
  EXPECT_LE(max_yaw_step, 0.06 + 1e-6);
  EXPECT_GT(max_yaw_step, 0.03);

  // Back to the robot's limits, and an unknown motion is refused by name.
  const PathOptions robot = WithMotion(spec.options, PathMotion::kRobot);
  EXPECT_EQ(robot.camera_rate_hz, PathOptions().camera_rate_hz);
  EXPECT_EQ(robot.max_speed_m_s, PathOptions().max_speed_m_s);
  EXPECT_THROW(PathMotionFromName("bicycle", "--motion"), InputError);
}

TEST(PathTest, AccelerationFromRestFollowsConstantAcceleration) {
  const std::vector<RouteSample> route = PlanRoute(LoopSpec());
  // s = a t^2 / 2 with a = 0.5 m/s^2 until 1 m/s (s = 1 m).
  for (double s : {0.04, 0.25, 0.81}) {
    const RouteSample& sample =
        route[static_cast<std::size_t>(std::lround(s / kRouteSampleSpacing))];
    EXPECT_NEAR(sample.time_s, std::sqrt(2.0 * sample.distance_m / 0.5), 1e-9) << s;
  }
}

TEST(PathTest, CornersAreArcsTangentToTheSegments) {
  PathSpec spec;
  spec.waypoints = {{0, 0}, {10, 0}, {10, 10}};
  spec.options.turn_radius_m = 2.0;
  const std::vector<RouteSample> route = PlanRoute(spec);
  // Closest approach to the corner of a 90-degree arc: r (sqrt(2) - 1).
  double closest = 1e9;
  for (const RouteSample& sample : route) {
    closest = std::min(closest, std::hypot(sample.x - 10.0, sample.y));
  }
  EXPECT_NEAR(closest, 2.0 * (std::sqrt(2.0) - 1.0), 1e-4);
  EXPECT_NEAR(RouteLength(route), 8.0 + 8.0 + kPi, 1e-9);
  // Continuous position and heading.
  for (std::size_t i = 1; i < route.size(); ++i) {
    const double step = std::hypot(route[i].x - route[i - 1].x, route[i].y - route[i - 1].y);
    EXPECT_NEAR(step, route[i].distance_m - route[i - 1].distance_m, 1e-5);
    EXPECT_LT(std::abs(std::remainder(route[i].heading_rad - route[i - 1].heading_rad, 2 * kPi)),
              0.0051);
  }
  EXPECT_NEAR(route.back().heading_rad, kPi / 2, 1e-12);
}

TEST(PathTest, ShortSegmentsShrinkTheRadius) {
  PathSpec spec;  // a U-turn 1 m wide with a 2 m default radius: each corner gets 0.5 m
  spec.waypoints = {{0, 0}, {5, 0}, {5, 1}, {0, 1}};
  spec.options.turn_radius_m = 2.0;
  const std::vector<RouteSample> route = PlanRoute(spec);
  double max_curvature = 0.0;
  for (const RouteSample& sample : route) max_curvature = std::max(max_curvature, sample.curvature);
  EXPECT_NEAR(max_curvature, 2.0, 1e-12);
  EXPECT_NEAR(RouteLength(route), 4.5 + 4.5 + kPi * 0.5, 1e-9);
}

TEST(PathTest, LoopReturnsToStartWithTightTurnAndCameraConvention) {
  const PathSpec spec = LoopSpec();
  for (PathRun run : {PathRun::kTeach, PathRun::kRepeat}) {
    const std::vector<TimedPose> poses = GenerateCameraPath(spec, run);
    ASSERT_GT(poses.size(), 100u);
    const Eigen::Vector3d start = poses.front().world_from_cam.translation;
    const Eigen::Vector3d end = poses.back().world_from_cam.translation;
    EXPECT_LT((end - start).norm(), 0.5);
    EXPECT_NEAR(start.x(), 0.0, 1e-12);
    for (const TimedPose& pose : poses) {
      EXPECT_NEAR(pose.world_from_cam.translation.z(), 0.6, 1e-12);
      // Camera y points down (up to vibration), x is horizontal-ish.
      const Eigen::Vector3d down = pose.world_from_cam.rotation * Eigen::Vector3d::UnitY();
      EXPECT_LT(std::acos(std::clamp(-down.z(), -1.0, 1.0)), 0.02);
    }
    // The camera looks where it goes.
    for (std::size_t i = 1; i < poses.size(); ++i) {
      const Eigen::Vector3d motion =
          poses[i].world_from_cam.translation - poses[i - 1].world_from_cam.translation;
      if (motion.norm() < 0.01) continue;
      const Eigen::Vector3d forward = poses[i].world_from_cam.rotation * Eigen::Vector3d::UnitZ();
      EXPECT_GT(forward.dot(motion.normalized()), 0.99) << "frame " << i;
    }
    // A heading change of at least 150 degrees within 5 m of travel (the U-turn).
    double best = 0.0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      double travelled = 0.0, turned = 0.0;
      for (std::size_t j = i + 1; j < poses.size() && travelled < 5.0; ++j) {
        travelled +=
            (poses[j].world_from_cam.translation - poses[j - 1].world_from_cam.translation).norm();
        turned += std::remainder(
            Heading(poses[j].world_from_cam) - Heading(poses[j - 1].world_from_cam), 2 * kPi);
        best = std::max(best, std::abs(turned));
      }
    }
    EXPECT_GE(best * 180.0 / kPi, 150.0);
  }
}

TEST(PathTest, RepeatDeviatesSmoothlyAndSlightly) {
  const PathSpec spec = LoopSpec();
  const std::vector<TimedPose> teach = GenerateCameraPath(spec, PathRun::kTeach);
  const std::vector<TimedPose> repeat = GenerateCameraPath(spec, PathRun::kRepeat);
  ASSERT_EQ(teach.size(), repeat.size());
  double max_offset = 0.0;
  for (std::size_t i = 0; i < teach.size(); ++i) {
    // Same time, same arc length: the offset is the lateral deviation.
    const double offset =
        (repeat[i].world_from_cam.translation - teach[i].world_from_cam.translation).norm();
    max_offset = std::max(max_offset, offset);
  }
  EXPECT_LE(max_offset, spec.options.repeat_deviation_m + 1e-9);
  EXPECT_GE(max_offset, 0.3 * spec.options.repeat_deviation_m);
  // Both runs start and stop at the same dock: the deviation tapers to zero at the ends.
  EXPECT_EQ(repeat.front().world_from_cam.translation, teach.front().world_from_cam.translation);
  EXPECT_LT(
      (repeat.back().world_from_cam.translation - teach.back().world_from_cam.translation).norm(),
      1e-3);
}

TEST(PathTest, SameSpecGivesSamePosesAndSeedChangesThem) {
  PathSpec spec = LoopSpec();
  const std::vector<TimedPose> a = GenerateCameraPath(spec, PathRun::kRepeat);
  const std::vector<TimedPose> b = GenerateCameraPath(spec, PathRun::kRepeat);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].world_from_cam.translation, b[i].world_from_cam.translation);
    ASSERT_EQ(a[i].world_from_cam.rotation.coeffs(), b[i].world_from_cam.rotation.coeffs());
  }
  spec.options.seed = 2;
  const std::vector<TimedPose> c = GenerateCameraPath(spec, PathRun::kRepeat);
  EXPECT_GT(
      (a[a.size() / 2].world_from_cam.translation - c[c.size() / 2].world_from_cam.translation)
          .norm(),
      1e-4);
}

TEST(PathTest, VibrationIsSmallAndOffWhenAsked) {
  PathSpec spec = LoopSpec();
  spec.options.vibration_rad = 0.0;
  spec.options.camera_pitch_rad = 0.1;
  for (const TimedPose& pose : GenerateCameraPath(spec, PathRun::kTeach)) {
    const Eigen::Vector3d forward = pose.world_from_cam.rotation * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d right = pose.world_from_cam.rotation * Eigen::Vector3d::UnitX();
    ASSERT_NEAR(std::asin(forward.z()), 0.1, 1e-12);  // positive pitch looks up
    ASSERT_NEAR(right.z(), 0.0, 1e-12);               // no roll
  }
}

TEST(PathTest, UndrivableRoutesAreInputErrors) {
  PathSpec spec;
  spec.waypoints = {{0, 0}};
  EXPECT_THROW(PlanRoute(spec), InputError);
  spec.waypoints = {{0, 0}, {5, 0}, {0, 0.1}};  // turns back by ~179 degrees
  EXPECT_NE(PathSpecProblem(spec).find("waypoints[1]"), std::string::npos);
  EXPECT_THROW(PlanRoute(spec), InputError);
  spec.waypoints = {{0, 0}, {5, 0}, {5.01, 0}};
  EXPECT_NE(PathSpecProblem(spec).find("waypoints[2]"), std::string::npos);
  spec.waypoints = {{0, 0}, {5, 0}};
  spec.options.camera_height_m = 1.5;
  EXPECT_NE(PathSpecProblem(spec).find("camera_height_m"), std::string::npos);
  spec.options.camera_height_m = 0.6;
  EXPECT_EQ(PathSpecProblem(spec), "");
}

}  // namespace
}  // namespace arucoslam
