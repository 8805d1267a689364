#include "arucoslam/slam/loaded_map_relocalizer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <vector>

#include "arucoslam/slam/synthetic_route_map.h"

namespace arucoslam {
namespace {

// A map as loaded from a file: keyframes every 9 degrees along an arc of the route circle,
// their points at the true wall positions.
struct LoadedArc {
  explicit LoadedArc(int num_keyframes, std::uint32_t seed = 5)
      : route([seed] {
          SyntheticRouteOptions options;
          options.seed = seed;
          return options;
        }()) {
    std::vector<Rigid3> poses;
    for (int k = 0; k < num_keyframes; ++k) poses.push_back(route.CamFromWorld(9.0 * k));
    route.AddRoute(poses, &map);
  }
  SyntheticRoute route;
  Map map;
};

double CentreError(const Rigid3& a, const Rigid3& b) {
  return (a.Inverse().translation - b.Inverse().translation).norm();
}

double AngleErrorDeg(const Rigid3& a, const Rigid3& b) {
  return Eigen::AngleAxisd(a.rotation.conjugate() * b.rotation).angle() * 180.0 / M_PI;
}

TEST(LoadedMapRelocalizerTest, AFrameOfTheMappedPlaceIsLocalisedNearItsTruePose) {
  LoadedArc arc(6);
  // Between keyframes 2 and 3, turned 4 degrees and 0.3 m off the route.
  const Rigid3 truth = arc.route.CamFromWorld(22.0, 4.0, 0.3);
  std::vector<int> truth_points;
  Frame frame = arc.route.MakeFrame(FrameId(100), truth, 150, &truth_points);
  LoadedMapRelocalizer relocalizer{TrackerOptions()};
  const std::optional<Rigid3> seed = relocalizer.SeedPose(arc.map, frame);
  ASSERT_TRUE(seed.has_value());
  EXPECT_LT(CentreError(*seed, truth), 0.05);
  EXPECT_LT(AngleErrorDeg(*seed, truth), 0.5);
  Tracker tracker(arc.map);
  const std::optional<int> num_inliers = relocalizer.Relocalize(arc.map, tracker, frame, 0);
  ASSERT_TRUE(num_inliers.has_value());
  EXPECT_GE(*num_inliers, TrackerOptions().min_local_map_inliers);
  EXPECT_EQ(tracker.state(), TrackingState::kTracking);
  ASSERT_TRUE(frame.cam_from_world.has_value());
  EXPECT_LT(CentreError(*frame.cam_from_world, truth), 0.05);
  EXPECT_LT(AngleErrorDeg(*frame.cam_from_world, truth), 0.5);
}

TEST(LoadedMapRelocalizerTest, AnUnrelatedFrameIsRefusedAndTrackingStaysStopped) {
  LoadedArc arc(6);
  // Another wall altogether (other descriptors) seen from a mapped pose.
  LoadedArc other(1, /*seed=*/99);
  std::vector<int> truth_points;
  Frame stranger =
      other.route.MakeFrame(FrameId(100), other.route.CamFromWorld(18.0), 150, &truth_points);
  LoadedMapRelocalizer relocalizer{TrackerOptions()};
  Tracker tracker(arc.map);
  EXPECT_FALSE(relocalizer.Relocalize(arc.map, tracker, stranger, 0).has_value());
  EXPECT_EQ(tracker.state(), TrackingState::kNotInitialized);
  EXPECT_FALSE(stranger.cam_from_world.has_value());
}

TEST(LoadedMapRelocalizerTest, KeyframesAreSearchedInTurnAcrossFrames) {
  // 16 keyframes: a frame is compared with 8 of them, the next frame with the other 8.
  LoadedArc arc(16);
  const Rigid3 truth = arc.route.CamFromWorld(9.0 * 13 + 2.0);  // near keyframe 13
  std::vector<int> truth_points;
  const Frame frame = arc.route.MakeFrame(FrameId(100), truth, 150, &truth_points);
  LoadedMapRelocalizer relocalizer{TrackerOptions()};
  EXPECT_FALSE(relocalizer.SeedPose(arc.map, frame).has_value()) << "keyframes 0-7 only";
  const std::optional<Rigid3> seed = relocalizer.SeedPose(arc.map, frame);
  ASSERT_TRUE(seed.has_value()) << "keyframes 8-15";
  EXPECT_LT(CentreError(*seed, truth), 0.05);
}

}  // namespace
}  // namespace arucoslam
