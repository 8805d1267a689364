#include "arucoslam/optim/global_bundle_adjustment.h"

#include <gtest/gtest.h>

#include <random>

#include "arucoslam/optim/synthetic_scene.h"

namespace arucoslam {
namespace {

// A map from a synthetic scene (0.5 px noise): keyframe i has one keypoint per observation
// of pose i. Keyframes from `first_perturbed` on and every point start off the truth.
struct SceneMap {
  BundleAdjustmentProblem truth;
  Map map;
  std::vector<KeyframeId> keyframes;
  std::vector<MapPointId> points;
};

Keyframe MakeKeyframe(const BundleAdjustmentProblem& truth, std::size_t pose_index,
                      const Rigid3& cam_from_world, const std::vector<MapPointId>& points) {
  const PinholeIntrinsics& k = truth.intrinsics;
  Keyframe keyframe;
  keyframe.camera.width = 640;
  keyframe.camera.height = 480;
  keyframe.camera.fx = k.fx;
  keyframe.camera.fy = k.fy;
  keyframe.camera.cx = k.cx;
  keyframe.camera.cy = k.cy;
  keyframe.features.pyramid = ScalePyramid::Make(8, 1.2);
  keyframe.cam_from_world = cam_from_world;
  for (const auto& observation : truth.observations) {
    if (observation.pose_index != pose_index) continue;
    cv::KeyPoint keypoint(observation.pixel.x(), observation.pixel.y(), 31.0f);
    keypoint.octave = 0;
    keyframe.features.keypoints.push_back(keypoint);
    keyframe.features.undistorted.emplace_back((observation.pixel.x() - k.cx) / k.fx,
                                               (observation.pixel.y() - k.cy) / k.fy);
    keyframe.map_point_ids.push_back(points[observation.point_index]);
  }
  keyframe.features.descriptors =
      cv::Mat::zeros(static_cast<int>(keyframe.features.size()), kOrbDescriptorBytes, CV_8U);
  return keyframe;
}

void Build(SceneMap& scene, std::size_t first_perturbed) {
  SyntheticSceneOptions options;
  options.noise_px = 0.5;
  options.num_points = 400;
  scene.truth = MakeSyntheticScene(options);
  std::mt19937 random(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  scene.map.Write([&](MapData& data) {
    for (const auto& point : scene.truth.points) {
      MapPoint map_point;
      map_point.p_in_world =
          point.p_in_world + 0.05 * Eigen::Vector3d(normal(random), normal(random), normal(random));
      scene.points.push_back(data.AddMapPoint(map_point));
    }
    for (std::size_t i = 0; i < scene.truth.poses.size(); ++i) {
      Rigid3 pose = scene.truth.poses[i].cam_from_world;
      if (i >= first_perturbed) {
        Vector6d delta;
        for (int c = 0; c < 6; ++c) delta[c] = 0.01 * normal(random);
        pose = Rigid3::Exp(delta) * pose;
      }
      scene.keyframes.push_back(data.AddKeyframe(MakeKeyframe(scene.truth, i, pose, scene.points)));
    }
  });
}

double MaxCentreError(const SceneMap& scene) {
  return scene.map.Read([&](const MapData& data) {
    double worst = 0.0;
    for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
      const Rigid3& truth = scene.truth.poses[i].cam_from_world;
      worst = std::max(worst, (data.FindKeyframe(scene.keyframes[i])->CameraCenter() -
                               truth.Inverse().translation)
                                  .norm());
    }
    return worst;
  });
}

TEST(GlobalBundleAdjustmentTest, WholeMapConvergesWithTwoFixedKeyframes) {
  SceneMap scene;
  Build(scene, 2);
  const double before = MaxCentreError(scene);
  GlobalBundleAdjustmentOptions options;
  options.num_fixed_keyframes = 2;  // frame and scale gauge
  const GlobalBundleAdjustmentResult result = RunGlobalBundleAdjustment(scene.map, options);
  ASSERT_TRUE(result.applied) << result.summary.message;
  SCOPED_TRACE(result.summary.BriefReport());
  EXPECT_EQ(result.num_keyframes, 10);
  EXPECT_EQ(result.num_points, 400);
  // Noise 0.5 px per axis: RMS of |r| = 0.5 sqrt(2) sqrt(1 - parameters / residuals).
  const double num_residuals = 2.0 * result.summary.num_residual_blocks;
  const double num_parameters = 3.0 * 400 + 6.0 * 8;
  EXPECT_NEAR(result.summary.final_rms_px,
              0.5 * std::sqrt(2.0) * std::sqrt(1.0 - num_parameters / num_residuals), 0.02);
  const double after = MaxCentreError(scene);
  std::printf("max camera centre error %.4f -> %.4f m\n", before, after);
  EXPECT_GT(before, 0.01);
  EXPECT_LT(after, 0.005);
  EXPECT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

// A keyframe and a point added while the solve ran (between snapshot and apply) keep their
// pose and position relative to the keyframe they hang from.
TEST(GlobalBundleAdjustmentTest, EntitiesAddedDuringTheSolveFollowTheirAnchor) {
  SceneMap scene;
  Build(scene, 2);
  GlobalBundleAdjustmentOptions options;
  options.num_fixed_keyframes = 2;
  GlobalBundleAdjustmentSnapshot snapshot =
      scene.map.Read([&](const MapData& data) { return TakeGlobalSnapshot(data, options); });
  GlobalBundleAdjustmentResult result;
  result.summary = SolveBundleAdjustment(options.solver, &snapshot.problem);
  ASSERT_TRUE(result.summary.success);

  const KeyframeId anchor = scene.keyframes.back();
  const Rigid3 offset(Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())),
                      Eigen::Vector3d(0.3, 0.0, 0.1));  // new_from_anchor
  KeyframeId added;
  MapPointId added_point;
  const Eigen::Vector3d point_in_new(0.2, -0.1, 4.0);
  scene.map.Write([&](MapData& data) {
    const Rigid3 anchor_pose = data.FindKeyframe(anchor)->cam_from_world;
    Keyframe keyframe = MakeKeyframe(scene.truth, 0, offset * anchor_pose, scene.points);
    keyframe.map_point_ids.assign(keyframe.map_point_ids.size(), MapPointId());
    added = data.AddKeyframe(std::move(keyframe), anchor);
    MapPoint point;
    point.p_in_world = (offset * anchor_pose).Inverse() * point_in_new;
    point.reference_keyframe = added;
    added_point = data.AddMapPoint(point);
    EXPECT_TRUE(data.AddObservation(added, 0, added_point));
  });
  scene.map.Write(
      [&](MapData& data) { ApplyGlobalBundleAdjustment(data, snapshot, options, &result); });
  EXPECT_EQ(result.num_corrected_keyframes, 1);
  EXPECT_EQ(result.num_corrected_points, 1);
  scene.map.Read([&](const MapData& data) {
    const Rigid3 anchor_pose = data.FindKeyframe(anchor)->cam_from_world;
    const Rigid3 added_pose = data.FindKeyframe(added)->cam_from_world;
    const Rigid3 relative = added_pose * anchor_pose.Inverse();
    EXPECT_LT((relative.translation - offset.translation).norm(), 1e-9);
    EXPECT_LT(RotationAngle(relative.rotation.conjugate() * offset.rotation), 1e-9);
    EXPECT_LT((added_pose * data.FindMapPoint(added_point)->p_in_world - point_in_new).norm(),
              1e-9);
    // The anchor itself took its solved pose.
    EXPECT_LT((anchor_pose.Inverse().translation -
               scene.truth.poses.back().cam_from_world.Inverse().translation)
                  .norm(),
              0.005);
    EXPECT_EQ(data.CheckInvariants(), "");
  });
}

TEST(GlobalBundleAdjustmentTest, EmptyMapAndBadOptionsAreReported) {
  Map map;
  EXPECT_FALSE(RunGlobalBundleAdjustment(map).applied);
  GlobalBundleAdjustmentOptions options;
  options.num_fixed_keyframes = 0;
  EXPECT_FALSE(options.Check());
  EXPECT_FALSE(RunGlobalBundleAdjustment(map, options).applied);
}

}  // namespace
}  // namespace arucoslam
