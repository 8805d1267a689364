#include "arucoslam/slam/map_initializer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <map>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/slam/synthetic_features.h"

namespace arucoslam {
namespace {

// Frames of one synthetic scene (points 4-10 m ahead) from cameras moved sideways, with
// their true poses as marker locations when asked.
class MapInitializerTest : public ::testing::Test {
 protected:
  Frame FrameAt(double timestamp_s, double x_m) {
    const Rigid3 cam_from_world(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-x_m, 0.0, 0.0));
    std::vector<int> truth;
    return scene_.MakeFrame(FrameId(next_id_++), timestamp_s, cam_from_world, &truth);
  }
  static MarkerFix FixAt(double x_m) {
    MarkerFix fix;
    fix.world_from_cam = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(x_m, 0.0, 0.0));
    return fix;
  }
  InitializationStep Step(Frame& frame, const std::optional<MarkerFix>& fix = std::nullopt) {
    return initializer_.Step(map_, frame, fix, 0);
  }
  // The timestamp of the reference a frame 0.6 m beside `x_m` initialises with.
  double ReferenceOfTheMap(double timestamp_s, double x_m) {
    Frame frame = FrameAt(timestamp_s, x_m + 0.6);
    const InitializationStep step = Step(frame);
    EXPECT_TRUE(step.map.has_value()) << step.message;
    return step.map ? step.map->first.timestamp_s : -1.0;
  }

  SyntheticFeatureScene scene_{PinholeCamera(640, 480, 500.0)};
  MapInitializer initializer_{scene_.camera(), MapInitializerOptions()};
  Map map_;
  std::size_t next_id_ = 0;
};

TEST_F(MapInitializerTest, TwoViewsWithParallaxBuildTheFirstMap) {
  Frame first = FrameAt(0.0, 0.0);
  const InitializationStep reference = Step(first);
  EXPECT_FALSE(reference.attempted);
  EXPECT_FALSE(reference.map.has_value());
  EXPECT_EQ(reference.message, "initialisation reference");
  Frame second = FrameAt(0.5, 0.6);
  const InitializationStep step = Step(second);
  EXPECT_TRUE(step.attempted);
  ASSERT_TRUE(step.map.has_value()) << step.message;
  EXPECT_FALSE(step.map->in_world);
  EXPECT_FALSE(step.map->first_fix.has_value());
  EXPECT_EQ(step.map->first.timestamp_s, 0.0);
  EXPECT_GE(step.map->num_points, 200);
  EXPECT_EQ(map_.NumKeyframes(), 2u);
  ASSERT_TRUE(second.cam_from_world.has_value());
  // Monocular: the baseline direction is known, its length is the map's own.
  const Eigen::Vector3d centre = second.cam_from_world->Inverse().translation;
  EXPECT_GT(centre.normalized().x(), 0.99);
}

TEST_F(MapInitializerTest, AReferenceOlderThanTheGapIsReplacedAndKeptForTheBackfill) {
  Frame old = FrameAt(0.0, 0.0);
  Step(old);
  Frame late = FrameAt(3.5, 0.6);  // MapInitializerOptions::max_reference_gap_s is 3 s
  const InitializationStep replaced = Step(late);
  EXPECT_FALSE(replaced.attempted);
  EXPECT_FALSE(replaced.map.has_value());
  ASSERT_TRUE(replaced.for_backfill.has_value());
  EXPECT_EQ(replaced.for_backfill->timestamp_s, 0.0);
  EXPECT_EQ(ReferenceOfTheMap(4.0, 0.6), 3.5);
}

TEST_F(MapInitializerTest, AFrameWithoutParallaxGoesToTheBackfillAndTheReferenceStays) {
  Frame first = FrameAt(0.0, 0.0);
  Step(first);
  Frame still = FrameAt(0.5, 0.0);
  const InitializationStep step = Step(still);
  EXPECT_TRUE(step.attempted);
  EXPECT_FALSE(step.map.has_value());
  ASSERT_TRUE(step.for_backfill.has_value());
  EXPECT_EQ(step.for_backfill->timestamp_s, 0.5);
  EXPECT_EQ(map_.NumKeyframes(), 0u);
  EXPECT_EQ(ReferenceOfTheMap(1.0, 0.0), 0.0);
}

TEST_F(MapInitializerTest, AfterWaitingOnOneReferenceASmallerShareOfGoodPointsSuffices) {
  // A fifth of the points move along their epipolar lines against the camera's motion (seen
  // from the second frame they lie behind it): still inliers of the two-view geometry, but
  // not good points. Before relax_after_s 90% must be good, afterwards 70%.
  MapInitializerOptions options;
  options.two_view.relax_after_s = 2.5;
  options.two_view.relaxed_triangulated_fraction = 0.7;
  MapInitializer initializer(scene_.camera(), options);
  std::vector<int> reference_truth;
  Frame reference = scene_.MakeFrame(FrameId(next_id_++), 0.0, Rigid3(), &reference_truth);
  std::map<int, Eigen::Vector2d> reference_pixel;  // point index -> normalised, in the reference
  for (std::size_t i = 0; i < reference_truth.size(); ++i) {
    if (reference_truth[i] >= 0)
      reference_pixel[reference_truth[i]] = reference.features.undistorted[i];
  }
  initializer.Step(map_, reference, std::nullopt, 0);
  auto moved_frame = [&](double timestamp_s) {
    std::vector<int> truth;
    const Rigid3 cam_from_world(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.6, 0.0, 0.0));
    Frame frame = scene_.MakeFrame(FrameId(next_id_++), timestamp_s, cam_from_world, &truth);
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const auto seen = reference_pixel.find(truth[i]);
      if (truth[i] < 0 || truth[i] % 5 != 0 || seen == reference_pixel.end()) continue;
      // The disparity reversed (normalised x' = 2 x_reference - x), in pixels too.
      Eigen::Vector2d& normalised = frame.features.undistorted[i];
      const double shift = 2.0 * (seen->second.x() - normalised.x());
      normalised.x() += shift;
      frame.features.keypoints[i].pt.x += static_cast<float>(scene_.camera().fx * shift);
    }
    return frame;
  };
  Frame early = moved_frame(2.0);
  const InitializationStep refused = initializer.Step(map_, early, std::nullopt, 1);
  EXPECT_TRUE(refused.attempted);
  EXPECT_FALSE(refused.map.has_value());
  EXPECT_NE(refused.message.find("consistent"), std::string::npos) << refused.message;
  Frame late = moved_frame(2.6);
  const InitializationStep built = initializer.Step(map_, late, std::nullopt, 2);
  ASSERT_TRUE(built.map.has_value()) << built.message;
  EXPECT_EQ(built.map->first.timestamp_s, 0.0);
}

TEST_F(MapInitializerTest, TooFewFeaturesNeverMakeAReference) {
  Frame empty = FrameAt(0.0, 0.0);
  empty.features = OrbFeatures();
  empty.ResetMatches();
  const InitializationStep step = Step(empty);
  EXPECT_EQ(step.message, "too few features");
  Frame next = FrameAt(0.5, 0.6);
  EXPECT_EQ(Step(next).message, "initialisation reference");
}

TEST_F(MapInitializerTest, MarkerLocationsOnBothFramesBuildTheMapInTheWorld) {
  Frame without_fix = FrameAt(0.0, 0.0);
  Step(without_fix);
  // A frame with a marker location replaces a reference without one.
  Frame first = FrameAt(0.2, 0.1);
  const InitializationStep reference = Step(first, FixAt(0.1));
  EXPECT_EQ(reference.message, "initialisation reference (markers)");
  ASSERT_TRUE(reference.for_backfill.has_value());
  EXPECT_EQ(reference.for_backfill->timestamp_s, 0.0);
  Frame near = FrameAt(0.4, 0.4);  // 0.3 m: below the 0.5 m marker baseline
  const InitializationStep waiting = Step(near, FixAt(0.4));
  EXPECT_EQ(waiting.message, "waiting for a marker baseline");
  EXPECT_FALSE(waiting.map.has_value());
  Frame second = FrameAt(0.6, 0.8);
  const InitializationStep step = Step(second, FixAt(0.8));
  ASSERT_TRUE(step.map.has_value()) << step.message;
  EXPECT_TRUE(step.map->in_world);
  ASSERT_TRUE(step.map->first_fix.has_value());
  EXPECT_NEAR(step.map->first.cam_from_world->Inverse().translation.x(), 0.1, 0.02);
  EXPECT_NEAR(second.cam_from_world->Inverse().translation.x(), 0.8, 0.02);
}

}  // namespace
}  // namespace arucoslam
