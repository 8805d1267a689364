#include "arucoslam/slam/marker_initialization.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/slam/synthetic_features.h"

namespace arucoslam {
namespace {

// Two views of a synthetic scene (points 4-10 m ahead) from cameras `baseline_m` apart
// sideways; the marker locations are the true camera poses, the second one moved by
// `offset_m` sideways and turned by `turn_deg` about the camera's x axis.
struct MarkerViews {
  SyntheticFeatureScene scene{PinholeCamera(640, 480, 500.0)};
  Frame first, second;
  std::vector<int> truth1;
  Rigid3 world_from_first, world_from_second;
  Rigid3 true_world_from_second;
};

MarkerViews MakeMarkerViews(double baseline_m, double offset_m = 0.0, double turn_deg = 0.0) {
  MarkerViews views;
  const Rigid3 cam2_from_world(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d(-baseline_m, 0.0, 0.05));
  std::vector<int> truth2;
  views.first = views.scene.MakeFrame(FrameId(1), 0.0, Rigid3::Identity(), &views.truth1);
  views.second = views.scene.MakeFrame(FrameId(2), 0.5, cam2_from_world, &truth2);
  views.world_from_first = Rigid3::Identity();
  views.true_world_from_second = cam2_from_world.Inverse();
  views.world_from_second = Rigid3(
      views.true_world_from_second.rotation *
          Eigen::Quaterniond(Eigen::AngleAxisd(turn_deg * M_PI / 180.0, Eigen::Vector3d::UnitX())),
      views.true_world_from_second.translation + Eigen::Vector3d(offset_m, 0.0, 0.0));
  return views;
}

// The distances of the map's points (in the world) from the scene's, through the first
// frame's matches, sorted.
std::vector<double> SortedPointErrors(const MarkerViews& views, const Map& map) {
  std::vector<double> errors;
  map.Read([&](const MapData& data) {
    for (std::size_t i = 0; i < views.first.map_point_ids.size(); ++i) {
      const MapPoint* point = data.FindMapPoint(views.first.map_point_ids[i]);
      if (point == nullptr || views.truth1[i] < 0) continue;
      errors.push_back((point->p_in_world - views.scene.points()[views.truth1[i]]).norm());
    }
    return 0;
  });
  std::sort(errors.begin(), errors.end());
  return errors;
}

MarkerInitializationResult Initialize(MarkerViews& views, Map& map,
                                      const MarkerInitializationOptions& options = {}) {
  const MarkerInitializer initializer(options, InitializerOptions(), InitialMapOptions());
  return initializer.Initialize(map, views.first, views.second, views.world_from_first,
                                views.world_from_second, 0);
}

TEST(MarkerInitializerTest, TwoMarkerLocationsGiveAMapInTheWorldNearTheTruth) {
  MarkerViews views = MakeMarkerViews(0.6);
  Map map;
  const MarkerInitializationResult result = Initialize(views, map);
  ASSERT_EQ(result.status, MarkerInitializationStatus::kInWorld) << result.message;
  EXPECT_NEAR(result.baseline_m, 0.6, 0.01);
  EXPECT_EQ(map.NumKeyframes(), 2u);
  ASSERT_GE(result.map.num_points, 200);
  const std::vector<double> errors = SortedPointErrors(views, map);
  ASSERT_GE(errors.size(), 200u);
  // 0.3 px of keypoint noise over a 0.6 m baseline: about 0.07 m of depth error at 7 m.
  EXPECT_LT(errors[errors.size() / 2], 0.08) << "median point error, metres";
  EXPECT_LT(errors[errors.size() * 9 / 10], 0.25) << "90th percentile point error, metres";
  const Eigen::Vector3d second_centre = views.second.cam_from_world->Inverse().translation;
  EXPECT_LT((second_centre - views.true_world_from_second.translation).norm(), 0.02);
}

TEST(MarkerInitializerTest, ACentimetreOffMarkerPoseKeepsThePointsWithinAQuarterMetre) {
  // 1 cm along a 0.6 m baseline: the map's scale 1.7% off, about 0.12 m at 7 m.
  MarkerViews views = MakeMarkerViews(0.6, 0.01, 0.2);
  Map map;
  const MarkerInitializationResult result = Initialize(views, map);
  ASSERT_EQ(result.status, MarkerInitializationStatus::kInWorld) << result.message;
  const std::vector<double> errors = SortedPointErrors(views, map);
  ASSERT_GE(errors.size(), 200u);
  EXPECT_LT(errors[errors.size() / 2], 0.25) << "median point error, metres";
}

TEST(MarkerInitializerTest, ShortBaselineIsRefusedAndSaysWhy) {
  MarkerViews views = MakeMarkerViews(0.3);
  Map map;
  const MarkerInitializationResult result = Initialize(views, map);
  EXPECT_EQ(result.status, MarkerInitializationStatus::kShortBaseline);
  EXPECT_NE(result.message.find("baseline"), std::string::npos) << result.message;
  EXPECT_EQ(map.NumKeyframes(), 0u);
  EXPECT_FALSE(views.second.cam_from_world.has_value());
}

TEST(MarkerInitializerTest, TooLittleParallaxIsRefusedAndLeavesTheMapEmpty) {
  MarkerViews views = MakeMarkerViews(0.6);  // about 3-9 degrees of parallax
  Map map;
  MarkerInitializationOptions options;
  options.min_parallax_deg = 20.0;
  const MarkerInitializationResult result = Initialize(views, map, options);
  EXPECT_EQ(result.status, MarkerInitializationStatus::kRefused);
  EXPECT_NE(result.message.find("parallax"), std::string::npos) << result.message;
  EXPECT_EQ(map.NumKeyframes(), 0u);
}

}  // namespace
}  // namespace arucoslam
