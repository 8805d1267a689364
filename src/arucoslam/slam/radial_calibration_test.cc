// RadialCalibration on a synthetic route map: a calibration that lacks a radial term is
// refined back to the true (pinhole) camera, a correct one is left alone, and the attempts
// follow their keyframe-count schedule.
#include "arucoslam/slam/radial_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "arucoslam/optim/bundle_adjustment.h"
#include "arucoslam/slam/synthetic_route_map.h"

namespace arucoslam {
namespace {

// Reprojection RMS of the map with its keyframes' undistorted keypoints, pixels.
double MapRmsPx(const Map& map) {
  return map.Read([](const MapData& data) {
    double sum = 0.0;
    int count = 0;
    for (const auto& [id, point] : data.map_points()) {
      for (const auto& [observer, index] : point.observations) {
        const Keyframe& keyframe = *data.FindKeyframe(observer);
        const Eigen::Vector3d p = keyframe.cam_from_world * point.p_in_world;
        const Eigen::Vector2d x = keyframe.features.undistorted[index];
        const Eigen::Vector2d r(keyframe.camera.fx * (p.x() / p.z() - x.x()),
                                keyframe.camera.fy * (p.y() / p.z() - x.y()));
        sum += r.squaredNorm();
        ++count;
      }
    }
    return std::sqrt(sum / count);
  });
}

class RadialCalibrationTest : public ::testing::Test {
 protected:
  // 30 keyframes 2 degrees apart on the route circle, true poses and points.
  void SetUp() override {
    std::vector<Rigid3> poses;
    for (int k = 0; k < 30; ++k) poses.push_back(route_.CamFromWorld(2.0 * k));
    route_.AddRoute(poses, &map_);
  }
  SyntheticRoute route_;
  Map map_;
};

TEST_F(RadialCalibrationTest, RefinesACalibrationThatLacksARadialTerm) {
  // The map believes the camera has k1 = -0.03: its undistorted keypoints are warped by
  // about +0.03 x |x|^2 against the true pinhole rays.
  CameraModel camera = SyntheticRoute::Camera();
  camera.model = DistortionModel::kRadTan;
  camera.distortion[0] = -0.03;
  map_.Write([&](MapData& data) { data.RecalibrateKeyframes(camera); });
  const double rms_before = MapRmsPx(map_);

  RadialCalibration calibration;
  const RadialCalibrationStep step = calibration.MaybeRefine(map_, &camera);
  ASSERT_TRUE(step.attempted);
  EXPECT_TRUE(step.applied) << step.message;
  EXPECT_NEAR(step.k, 0.03, 0.004);
  EXPECT_NEAR(camera.distortion[0], 0.0, 0.004);  // back to the true camera
  EXPECT_LT(step.cost_with, 0.95 * step.cost_without);
  map_.Read([&](const MapData& data) {
    for (const auto& [id, keyframe] : data.keyframes()) {
      EXPECT_EQ(keyframe.camera.distortion[0], camera.distortion[0]);
    }
    return 0;
  });
  EXPECT_LT(MapRmsPx(map_), 0.5 * rms_before);
  EXPECT_EQ(calibration.num_applied(), 1);
}

TEST_F(RadialCalibrationTest, LeavesACorrectCalibrationAlone) {
  CameraModel camera = SyntheticRoute::Camera();
  RadialCalibration calibration;
  const RadialCalibrationStep step = calibration.MaybeRefine(map_, &camera);
  ASSERT_TRUE(step.attempted);
  EXPECT_FALSE(step.applied);
  EXPECT_EQ(step.message, "correction does not pay");
  EXPECT_LT(std::abs(step.k), 0.004);
  EXPECT_EQ(camera.model, DistortionModel::kNone);
}

TEST_F(RadialCalibrationTest, AttemptsFollowTheKeyframeSchedule) {
  CameraModel camera = SyntheticRoute::Camera();
  RadialCalibrationOptions options;
  options.first_keyframes = 40;
  EXPECT_FALSE(RadialCalibration(options).MaybeRefine(map_, &camera).attempted);  // 30 < 40

  options.first_keyframes = 12;  // attempts due at 12, 24, 48 keyframes
  RadialCalibration calibration(options);
  EXPECT_TRUE(calibration.MaybeRefine(map_, &camera).attempted);
  EXPECT_TRUE(calibration.MaybeRefine(map_, &camera).attempted);
  EXPECT_FALSE(calibration.MaybeRefine(map_, &camera).attempted);

  options.enabled = false;
  EXPECT_FALSE(RadialCalibration(options).MaybeRefine(map_, &camera).attempted);
  std::string why;
  options.first_keyframes = 2;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("first_keyframes"), std::string::npos) << why;
}

}  // namespace
}  // namespace arucoslam
