#include "arucoslam/optim/local_bundle_adjustment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <thread>

#include "arucoslam/optim/synthetic_scene.h"

namespace arucoslam {
namespace {

// A map made from a synthetic scene: keyframe i has one keypoint per observation of pose i,
// whose undistorted coordinates are the (noisy) observed pixel.
struct SyntheticMap {
  BundleAdjustmentProblem truth;
  Map map;
  std::vector<KeyframeId> keyframes;
  std::vector<MapPointId> points;
  // (keyframe index, keypoint index) of corrupted observations.
  std::vector<std::pair<int, int>> corrupted;
};

void Build(SyntheticMap& scene, int corrupt_every) {
  SyntheticSceneOptions options;
  options.noise_px = 0.5;
  scene.truth = MakeSyntheticScene(options);
  const PinholeIntrinsics& k = scene.truth.intrinsics;
  CameraModel camera;
  camera.width = options.image_width;
  camera.height = options.image_height;
  camera.fx = k.fx;
  camera.fy = k.fy;
  camera.cx = k.cx;
  camera.cy = k.cy;
  std::mt19937 random(4);
  std::normal_distribution<double> normal(0.0, 1.0);
  scene.map.Write([&](MapData& data) {
    for (const auto& point : scene.truth.points) {
      MapPoint map_point;
      map_point.p_in_world =
          point.p_in_world + 0.05 * Eigen::Vector3d(normal(random), normal(random), normal(random));
      scene.points.push_back(data.AddMapPoint(map_point));
    }
    for (std::size_t i = 0; i < scene.truth.poses.size(); ++i) {
      Keyframe keyframe;
      keyframe.camera = camera;
      keyframe.features.pyramid = ScalePyramid::Make(8, 1.2);
      keyframe.cam_from_world = scene.truth.poses[i].cam_from_world;
      if (i >= 4) {  // the window keyframes start off the truth
        Vector6d delta;
        for (int c = 0; c < 6; ++c) delta[c] = 0.01 * normal(random);
        keyframe.cam_from_world = Rigid3::Exp(delta) * keyframe.cam_from_world;
      }
      for (const auto& observation : scene.truth.observations) {
        if (observation.pose_index != i) continue;
        Eigen::Vector2d pixel = observation.pixel;
        const int index = static_cast<int>(keyframe.features.keypoints.size());
        if (corrupt_every > 0 && (index + static_cast<int>(i)) % corrupt_every == 0) {
          pixel += Eigen::Vector2d(25.0, -20.0);
          scene.corrupted.emplace_back(static_cast<int>(i), index);
        }
        cv::KeyPoint keypoint(pixel.x(), pixel.y(), 31.0f);
        keypoint.octave = 0;
        keyframe.features.keypoints.push_back(keypoint);
        keyframe.features.undistorted.push_back(
            Eigen::Vector2d((pixel.x() - k.cx) / k.fx, (pixel.y() - k.cy) / k.fy));
        keyframe.map_point_ids.push_back(scene.points[observation.point_index]);
      }
      keyframe.features.descriptors =
          cv::Mat::zeros(static_cast<int>(keyframe.features.size()), kOrbDescriptorBytes, CV_8U);
      scene.keyframes.push_back(data.AddKeyframe(std::move(keyframe)));
    }
  });
}

double MaxPoseError(const SyntheticMap& scene, int first, int last) {
  return scene.map.Read([&](const MapData& data) {
    double worst = 0.0;
    for (int i = first; i <= last; ++i) {
      const Rigid3& estimate = data.FindKeyframe(scene.keyframes[i])->cam_from_world;
      const Rigid3& truth = scene.truth.poses[i].cam_from_world;
      worst =
          std::max(worst, (estimate.Inverse().translation - truth.Inverse().translation).norm());
    }
    return worst;
  });
}

double MedianPointError(const SyntheticMap& scene) {
  std::vector<double> errors = scene.map.Read([&](const MapData& data) {
    std::vector<double> result;
    for (std::size_t j = 0; j < scene.points.size(); ++j) {
      if (const MapPoint* point = data.FindMapPoint(scene.points[j])) {
        result.push_back((point->p_in_world - scene.truth.points[j].p_in_world).norm());
      }
    }
    return result;
  });
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

TEST(LocalBundleAdjustmentTest, WindowConvergesAndBorderStaysFixed) {
  SyntheticMap scene;
  Build(scene, 0);
  ASSERT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
  const double pose_error_before = MaxPoseError(scene, 4, 9);
  const double point_error_before = MedianPointError(scene);
  EXPECT_GT(pose_error_before, 0.01);
  EXPECT_GT(point_error_before, 0.05);

  LocalBundleAdjustmentOptions options;
  options.max_covisible_keyframes = 5;
  const LocalBundleAdjustmentResult result =
      RunLocalBundleAdjustment(scene.map, scene.keyframes[9], options);
  ASSERT_TRUE(result.applied) << result.summary.message;
  SCOPED_TRACE(result.summary.BriefReport());
  // Every keyframe sees most points, so the best five covisible ones are 4..8 (the nearest
  // share most) and 0..3 form the fixed border.
  EXPECT_EQ(result.num_local_keyframes, 6);
  EXPECT_EQ(result.num_fixed_keyframes, 4);
  EXPECT_EQ(MaxPoseError(scene, 0, 3), 0.0);
  // Same accuracy as the full problem in bundle_adjustment_test: millimetres.
  EXPECT_LT(MaxPoseError(scene, 4, 9), 0.005);
  EXPECT_LT(MedianPointError(scene), 0.02);
  EXPECT_EQ(result.num_erased_observations, 0);
  EXPECT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

// Border keyframes that see only two window points each barely hold the gauge (Ceres'
// Cholesky failed on such windows): the oldest window keyframes are fixed as well.
TEST(LocalBundleAdjustmentTest, WeakBorderKeyframesAreNotTheOnlyAnchors) {
  SyntheticMap scene;
  Build(scene, 0);
  scene.map.Write([&](MapData& data) {
    for (int i = 0; i < 4; ++i) {
      const std::vector<MapPointId> seen = data.MapPointsOf(scene.keyframes[i]);
      for (std::size_t k = 2; k < seen.size(); ++k) data.EraseObservation(scene.keyframes[i], seen[k]);
    }
    // The two keyframes that will anchor the window start on the truth.
    for (int i = 4; i < 6; ++i) {
      data.SetKeyframePose(scene.keyframes[i], scene.truth.poses[i].cam_from_world);
    }
    return 0;
  });
  const Rigid3 oldest_before = scene.map.Read(
      [&](const MapData& data) { return data.FindKeyframe(scene.keyframes[4])->cam_from_world; });
  LocalBundleAdjustmentOptions options;
  options.max_covisible_keyframes = 5;
  options.min_fixed_keyframes = 2;
  const LocalBundleAdjustmentResult result =
      RunLocalBundleAdjustment(scene.map, scene.keyframes[9], options);
  ASSERT_TRUE(result.applied) << result.summary.message;
  SCOPED_TRACE(result.summary.BriefReport());
  EXPECT_EQ(result.num_local_keyframes, 6);
  EXPECT_EQ(result.num_fixed_keyframes, 6);  // 4 weak border + keyframes 4 and 5
  const Rigid3 oldest_after = scene.map.Read(
      [&](const MapData& data) { return data.FindKeyframe(scene.keyframes[4])->cam_from_world; });
  EXPECT_EQ((oldest_after.translation - oldest_before.translation).norm(), 0.0);
  // Anchored on true poses, the free keyframes converge as in the full problem: millimetres.
  EXPECT_LT(MaxPoseError(scene, 6, 9), 0.005);
  options.min_anchor_points = 2;  // the two points count: only the border is fixed
  SyntheticMap again;
  Build(again, 0);
  again.map.Write([&](MapData& data) {
    for (int i = 0; i < 4; ++i) {
      const std::vector<MapPointId> seen = data.MapPointsOf(again.keyframes[i]);
      for (std::size_t k = 2; k < seen.size(); ++k) data.EraseObservation(again.keyframes[i], seen[k]);
    }
    return 0;
  });
  EXPECT_EQ(RunLocalBundleAdjustment(again.map, again.keyframes[9], options).num_fixed_keyframes, 4);
}

TEST(LocalBundleAdjustmentTest, ErasesOutlierObservations) {
  SyntheticMap scene;
  Build(scene, 40);
  LocalBundleAdjustmentOptions options;
  options.max_covisible_keyframes = 9;  // the whole map; keyframe 0 is fixed as the first
  const LocalBundleAdjustmentResult result =
      RunLocalBundleAdjustment(scene.map, scene.keyframes[9], options);
  ASSERT_TRUE(result.applied) << result.summary.message;
  EXPECT_EQ(result.num_fixed_keyframes, 1);
  // Every corrupted observation (30 px off) is gone, and hardly anything else.
  const int remaining = scene.map.Read([&](const MapData& data) {
    int count = 0;
    for (const auto& [pose, index] : scene.corrupted) {
      count += data.FindKeyframe(scene.keyframes[pose])->map_point_ids[index].IsValid() ? 1 : 0;
    }
    return count;
  });
  EXPECT_EQ(remaining, 0);
  const int num_corrupted = static_cast<int>(scene.corrupted.size());
  EXPECT_GE(result.num_erased_observations, num_corrupted);
  EXPECT_LT(result.num_erased_observations, num_corrupted + num_corrupted / 10);
  EXPECT_LT(MedianPointError(scene), 0.02);
  EXPECT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

// Points moved next to a window keyframe's centre (2% of its median depth, as bad matches
// triangulated there): their observations are left out of the solve and erased, the rest
// of the window converges as without them. Included, these made Ceres' Cholesky fail.
TEST(LocalBundleAdjustmentTest, PointsNextToACameraAreLeftOut) {
  SyntheticMap scene;
  Build(scene, 0);
  const int num_near = 5;
  std::vector<MapPointId> near;
  scene.map.Write([&](MapData& data) {
    const Keyframe& keyframe = *data.FindKeyframe(scene.keyframes[9]);
    const Rigid3 world_from_cam = keyframe.cam_from_world.Inverse();
    for (int k = 0; k < num_near; ++k) {
      const MapPointId id = keyframe.map_point_ids[10 * k];
      const Eigen::Vector3d p_in_world = data.FindMapPoint(id)->p_in_world;
      const double depth = (keyframe.cam_from_world * p_in_world).z();
      // The same ray from the camera, at 2% of the depth.
      const Eigen::Vector3d near_point =
          world_from_cam.translation + 0.02 * (p_in_world - world_from_cam.translation);
      ASSERT_GT(depth, 1.0);
      data.SetMapPointPosition(id, near_point);
      near.push_back(id);
    }
  });
  LocalBundleAdjustmentOptions options;
  options.max_covisible_keyframes = 5;
  const LocalBundleAdjustmentResult result =
      RunLocalBundleAdjustment(scene.map, scene.keyframes[9], options);
  ASSERT_TRUE(result.applied) << result.summary.message;
  // Each moved point is too near keyframe 9 and behind or too near most others.
  EXPECT_GE(result.num_too_near_observations, num_near);
  scene.map.Read([&](const MapData& data) {
    const Keyframe& keyframe = *data.FindKeyframe(scene.keyframes[9]);
    for (const MapPointId& id : near) {
      EXPECT_EQ(std::count(keyframe.map_point_ids.begin(), keyframe.map_point_ids.end(), id), 0);
    }
  });
  EXPECT_LT(MaxPoseError(scene, 4, 9), 0.005);
  EXPECT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

// Another thread erases points and a window keyframe while the solve runs without the
// lock: the write-back must skip what is gone and leave a consistent map.
TEST(LocalBundleAdjustmentTest, ConcurrentErasuresDuringTheSolve) {
  SyntheticMap scene;
  Build(scene, 0);
  LocalBundleAdjustmentOptions options;
  options.max_covisible_keyframes = 5;
  LocalBundleAdjustmentResult result;
  std::thread solver(
      [&] { result = RunLocalBundleAdjustment(scene.map, scene.keyframes[9], options); });
  std::thread eraser([&] {
    for (std::size_t j = 0; j < scene.points.size(); j += 3) {
      scene.map.Write([&](MapData& data) { data.EraseMapPoint(scene.points[j]); });
    }
    scene.map.Write([&](MapData& data) { data.EraseKeyframe(scene.keyframes[6]); });
  });
  solver.join();
  eraser.join();
  ASSERT_TRUE(result.applied) << result.summary.message;
  EXPECT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
  EXPECT_EQ(scene.map.NumKeyframes(), 9u);
  scene.map.Read([&](const MapData& data) {
    for (std::size_t j = 0; j < scene.points.size(); j += 3) {
      EXPECT_EQ(data.FindMapPoint(scene.points[j]), nullptr);
    }
  });
}

}  // namespace
}  // namespace arucoslam
