#include "arucoslam/optim/marker_factors.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>

#include "arucoslam/geometry/pose_information.h"
#include "arucoslam/optim/global_bundle_adjustment.h"
#include "arucoslam/optim/local_bundle_adjustment.h"
#include "arucoslam/optim/marker_bundle_adjustment_synthetic.h"

namespace arucoslam {
namespace {

// A Map and MarkerLandmarks made from a synthetic marker scene: keyframe i has one keypoint
// per keypoint observation of pose i (its undistorted coordinates are the observed pixel);
// marker m is landmark id 10 + m with the scene's corner observations.
struct MarkerSceneMap {
  MarkerBundleAdjustmentProblem truth;
  Map map;
  MarkerLandmarks landmarks;
  std::vector<KeyframeId> keyframes;
};

// Keyframes and points start at the truth moved by `map_from_truth` (keyframe 0 excepted).
void Build(MarkerSceneMap& scene, const Sim3& map_from_truth) {
  SyntheticMarkerSceneOptions options;
  options.noise_px = 0.5;
  options.corner_noise_px = 0.3;
  scene.truth = MakeSyntheticMarkerScene(options);
  const BundleAdjustmentProblem& truth = scene.truth.keypoints;
  const PinholeIntrinsics& k = truth.intrinsics;
  CameraModel camera;
  camera.width = options.image_width;
  camera.height = options.image_height;
  camera.fx = k.fx;
  camera.fy = k.fy;
  camera.cx = k.cx;
  camera.cy = k.cy;
  scene.map.Write([&](MapData& data) {
    std::vector<MapPointId> points;
    for (const auto& point : truth.points) {
      MapPoint map_point;
      map_point.p_in_world = map_from_truth * point.p_in_world;
      points.push_back(data.AddMapPoint(map_point));
    }
    for (std::size_t i = 0; i < truth.poses.size(); ++i) {
      Keyframe keyframe;
      keyframe.camera = camera;
      keyframe.features.pyramid = ScalePyramid::Make(8, 1.2);
      const Rigid3& true_pose = truth.poses[i].cam_from_world;
      keyframe.cam_from_world =
          i == 0 ? true_pose : map_from_truth.TransformPose(true_pose.Inverse()).Inverse();
      for (const auto& observation : truth.observations) {
        if (observation.pose_index != i) continue;
        const Eigen::Vector2d& pixel = observation.pixel;
        cv::KeyPoint keypoint(pixel.x(), pixel.y(), 31.0f);
        keypoint.octave = 0;
        keyframe.features.keypoints.push_back(keypoint);
        keyframe.features.undistorted.push_back(
            Eigen::Vector2d((pixel.x() - k.cx) / k.fx, (pixel.y() - k.cy) / k.fy));
        keyframe.map_point_ids.push_back(points[observation.point_index]);
      }
      keyframe.features.descriptors =
          cv::Mat::zeros(static_cast<int>(keyframe.features.size()), kOrbDescriptorBytes, CV_8U);
      scene.keyframes.push_back(data.AddKeyframe(std::move(keyframe)));
    }
  });
  for (std::size_t m = 0; m < scene.truth.markers.size(); ++m) {
    MarkerLandmark landmark;
    landmark.id = MarkerId(10 + static_cast<int>(m));
    landmark.size = scene.truth.markers[m].size;
    landmark.world_from_marker = scene.truth.markers[m].world_from_marker;
    landmark.fixed = true;
    for (const auto& observation : scene.truth.marker_observations) {
      if (observation.marker_index != m) continue;
      landmark.observations[scene.keyframes[observation.pose_index]] = observation.corners_px;
    }
    scene.landmarks.Add(landmark);
  }
}

double MaxCentreError(const MarkerSceneMap& scene) {
  return scene.map.Read([&](const MapData& data) {
    double worst = 0.0;
    for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
      const Rigid3& estimate = data.FindKeyframe(scene.keyframes[i])->cam_from_world;
      const Rigid3& truth = scene.truth.keypoints.poses[i].cam_from_world;
      worst =
          std::max(worst, (estimate.Inverse().translation - truth.Inverse().translation).norm());
    }
    return worst;
  });
}

// A map 5% too large (monocular scale error) about the first camera.
Sim3 ScaleError() {
  return Sim3(1.05, Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, -0.05));
}

LocalBundleAdjustmentOptions WholeMapWindow() {
  LocalBundleAdjustmentOptions options;
  options.max_covisible_keyframes = 30;  // every keyframe; the first one is fixed
  options.min_fixed_keyframes = 1;
  options.solver.max_iterations = 30;
  return options;
}

TEST(MarkerFactorsTest, CollectsTheWindowsObservations) {
  MarkerSceneMap scene;
  Build(scene, Sim3());
  const std::vector<KeyframeId> window = {scene.keyframes[0], scene.keyframes[19]};
  const MarkerFactors factors = scene.map.Read([&](const MapData& data) {
    return CollectMarkerFactors(data, window, scene.landmarks);
  });
  int expected = 0;
  for (const auto& observation : scene.truth.marker_observations) {
    if (observation.pose_index == 0 || observation.pose_index == 19) ++expected;
  }
  ASSERT_GT(expected, 0);
  EXPECT_EQ(static_cast<int>(factors.observations.size()), expected);
  EXPECT_EQ(factors.markers.size(), factors.marker_ids.size());
  EXPECT_EQ(factors.num_fixed_markers, static_cast<int>(factors.markers.size()));
  for (const auto& observation : factors.observations) {
    EXPECT_LT(observation.pose_index, 2u);
    EXPECT_LT(observation.marker_index, factors.markers.size());
  }
}

// Without markers a monocular window keeps whatever scale it has; known markers' corners in
// the same solve bring it back to metric.
TEST(MarkerFactorsTest, LocalBundleAdjustmentWithKnownMarkersCorrectsTheScale) {
  MarkerSceneMap plain;
  Build(plain, ScaleError());
  const double error_before = MaxCentreError(plain);
  EXPECT_GT(error_before, 0.25);
  const LocalBundleAdjustmentResult without =
      RunLocalBundleAdjustment(plain.map, plain.keyframes[19], WholeMapWindow());
  ASSERT_TRUE(without.applied) << without.summary.message;
  EXPECT_EQ(without.num_marker_observations, 0);
  EXPECT_GT(MaxCentreError(plain), 0.2);

  MarkerSceneMap fused;
  Build(fused, ScaleError());
  const LocalBundleAdjustmentResult with = RunLocalBundleAdjustment(
      fused.map, fused.keyframes[19], WholeMapWindow(), &fused.landmarks);
  ASSERT_TRUE(with.applied) << with.summary.message;
  EXPECT_EQ(with.num_marker_observations, static_cast<int>(fused.truth.marker_observations.size()));
  EXPECT_EQ(with.num_moved_markers, 0);  // all fixed
  // Measured: 0.30 m before, 0.30 m after a solve without markers, 2.3 mm with them.
  EXPECT_LT(MaxCentreError(fused), 0.02) << with.summary.BriefReport();
  EXPECT_EQ(fused.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

// Global BA (after a loop, in the marker world): the known markers hold the gauge, so no
// keyframe is fixed and a map that is off in scale as a whole comes back; a mapped marker
// that starts off is estimated and written back to the landmarks.
TEST(MarkerFactorsTest, GlobalBundleAdjustmentWithMarkersFixesNoKeyframe) {
  GlobalBundleAdjustmentOptions options;
  options.solver.max_iterations = 30;
  MarkerSceneMap plain;
  Build(plain, ScaleError());
  const GlobalBundleAdjustmentResult without = RunGlobalBundleAdjustment(plain.map, options);
  ASSERT_TRUE(without.applied) << without.summary.message;
  EXPECT_EQ(without.num_marker_observations, 0);
  EXPECT_GT(MaxCentreError(plain), 0.2);  // two fixed keyframes keep the wrong scale

  MarkerSceneMap fused;
  Build(fused, ScaleError());
  MarkerLandmark unknown = *fused.landmarks.Find(MarkerId(11));
  const Rigid3 truth = unknown.world_from_marker;
  unknown.fixed = false;
  unknown.world_from_marker = Rigid3(Eigen::Quaterniond::Identity(),
                                     Eigen::Vector3d(0.05, 0.0, -0.05)) * truth;
  fused.landmarks.Erase(MarkerId(11));
  fused.landmarks.Add(unknown);
  const GlobalBundleAdjustmentSnapshot snapshot = fused.map.Read(
      [&](const MapData& data) { return TakeGlobalSnapshot(data, options, &fused.landmarks); });
  for (const auto& pose : snapshot.problem.poses) EXPECT_FALSE(pose.fixed);
  const GlobalBundleAdjustmentResult with =
      RunGlobalBundleAdjustment(fused.map, options, &fused.landmarks);
  ASSERT_TRUE(with.applied) << with.summary.message;
  EXPECT_EQ(with.num_marker_observations,
            static_cast<int>(fused.truth.marker_observations.size()));
  // Measured: 0.30 m without markers, 5.3 mm with them; the mapped marker 1.4 mm off.
  EXPECT_LT(MaxCentreError(fused), 0.02) << with.summary.BriefReport();
  const Rigid3& estimate = fused.landmarks.Find(MarkerId(11))->world_from_marker;
  EXPECT_LT((estimate.translation - truth.translation).norm(), 0.02);
  EXPECT_EQ(fused.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

TEST(MarkerFactorsTest, GlobalSnapshotCarriesThePositionPriorsOfItsKeyframes) {
  MarkerSceneMap scene;
  Build(scene, ScaleError());
  KeyframePosePrior prior;
  prior.keyframe = scene.keyframes[5];
  prior.world_from_cam = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(2.0, 0.1, 1.0));
  prior.information = Matrix6d::Identity() / (0.1 * 0.1);
  KeyframePosePrior elsewhere = prior;
  elsewhere.keyframe = KeyframeId(100000);  // no keyframe of this map
  const GlobalBundleAdjustmentSnapshot snapshot = scene.map.Read([&](const MapData& data) {
    return TakeGlobalSnapshot(data, {}, &scene.landmarks, {prior, elsewhere});
  });
  ASSERT_EQ(snapshot.markers.position_priors.size(), 1u);
  const PositionPrior& taken = snapshot.markers.position_priors.front();
  ASSERT_LT(taken.pose_index, snapshot.keyframe_ids.size());
  EXPECT_EQ(snapshot.keyframe_ids[taken.pose_index], scene.keyframes[5]);
  EXPECT_EQ(taken.centre_in_world, Eigen::Vector3d(2.0, 0.1, 1.0));
  EXPECT_NEAR(taken.sigma_m, 0.1, 1e-12);
}

TEST(MarkerFactorsTest, PositionPriorsJoinAGlobalSolveWithoutMarkers) {
  // Keypoints only, the map 5% too large: the last keyframe ends far from its true centre
  // unless a prior there takes part in the solve.
  const auto last_centre_error = [](const std::vector<KeyframePosePrior>& priors) {
    MarkerSceneMap scene;
    Build(scene, ScaleError());
    GlobalBundleAdjustmentOptions options;
    options.solver.max_iterations = 30;
    GlobalBundleAdjustmentSnapshot snapshot = scene.map.Read(
        [&](const MapData& data) { return TakeGlobalSnapshot(data, options, nullptr, priors); });
    EXPECT_EQ(snapshot.markers.position_priors.size(), priors.size());
    EXPECT_TRUE(SolveGlobalSnapshot(options, &snapshot).success);
    const std::size_t last = snapshot.keyframe_ids.size() - 1;
    return (snapshot.problem.poses[last].cam_from_world.Inverse().translation -
            scene.truth.keypoints.poses[last].cam_from_world.Inverse().translation)
        .norm();
  };
  MarkerSceneMap reference;
  Build(reference, ScaleError());
  KeyframePosePrior prior;
  prior.keyframe = reference.keyframes.back();
  prior.world_from_cam = reference.truth.keypoints.poses.back().cam_from_world.Inverse();
  prior.information = Matrix6d::Identity() / (0.01 * 0.01);
  const double without = last_centre_error({});
  const double with = last_centre_error({prior});
  std::printf("last keyframe centre error: %.4f m without the prior, %.4f m with it\n", without,
              with);
  // Measured: 0.30 m without, 9 mm with it.
  EXPECT_GT(without, 0.2);
  EXPECT_LT(with, 0.03);
}

TEST(MarkerFactorsTest, LocalBundleAdjustmentEstimatesAnUnknownMarker) {
  MarkerSceneMap scene;
  Build(scene, Sim3());
  // Marker 11 is not known: it starts 10 cm and a few degrees off its true pose.
  MarkerLandmark unknown = *scene.landmarks.Find(MarkerId(11));
  const Rigid3 truth = unknown.world_from_marker;
  unknown.fixed = false;
  unknown.world_from_marker =
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitZ())),
             Eigen::Vector3d(0.06, -0.05, 0.06)) *
      truth;
  scene.landmarks.Erase(MarkerId(11));
  scene.landmarks.Add(unknown);
  const LocalBundleAdjustmentResult result = RunLocalBundleAdjustment(
      scene.map, scene.keyframes[19], WholeMapWindow(), &scene.landmarks);
  ASSERT_TRUE(result.applied) << result.summary.message;
  EXPECT_EQ(result.num_moved_markers, 1);
  const Rigid3& estimate = scene.landmarks.Find(MarkerId(11))->world_from_marker;
  EXPECT_LT((estimate.translation - truth.translation).norm(), 0.02);
  EXPECT_LT(estimate.rotation.angularDistance(truth.rotation), 0.01);
  EXPECT_TRUE(scene.landmarks.Find(MarkerId(10))->fixed);
}

TEST(MarkerFactorsTest, PosePriorsComeFromTheFixedMarkersAlone) {
  MarkerSceneMap scene;
  // Keyframes far off (30 cm, 5% scale): the priors must not depend on them.
  Build(scene, Sim3(1.05, Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitZ())),
                    Eigen::Vector3d(0.3, 0.0, 0.0)));
  const std::vector<PoseGraphProblem::PosePrior> priors = scene.map.Read([&](const MapData& data) {
    return MarkerPosePriors(data, scene.keyframes, scene.landmarks);
  });
  std::set<std::size_t> seeing;
  for (const auto& observation : scene.truth.marker_observations) seeing.insert(observation.pose_index);
  ASSERT_GT(seeing.size(), 5u);
  EXPECT_EQ(priors.size(), seeing.size());
  for (const auto& prior : priors) {
    const Rigid3 truth = scene.truth.keypoints.poses[prior.node].cam_from_world.Inverse();
    // Corners with 0.3 px noise on 0.3 m markers up to 10 m away.
    EXPECT_LT((prior.world_from_cam.translation - truth.translation).norm(), 0.1) << prior.node;
    EXPECT_LT(prior.world_from_cam.rotation.angularDistance(truth.rotation), 0.02) << prior.node;
    EXPECT_GT(prior.information(0, 0), 0.0);
  }
}

// Priors from their corners are weaker for far markers (their pose error grows with distance),
// bound the priors' true error, are never firmer than the options' sigmas, and beyond
// max_prior_distance_sides there is none.
TEST(MarkerFactorsTest, PosePriorsFromCornersWeakenWithDistanceAndStopBeyondTheLimit) {
  MarkerSceneMap scene;
  Build(scene, Sim3());
  // Distance from a prior's camera to the nearest marker its keyframe saw, in marker sides.
  const auto nearest_sides = [&](const PoseGraphProblem::PosePrior& prior) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& [id, landmark] : scene.landmarks.landmarks()) {
      if (landmark.observations.count(scene.keyframes[prior.node]) == 0) continue;
      nearest = std::min(nearest, (landmark.world_from_marker.translation -
                                   prior.world_from_cam.translation).norm() / landmark.size);
    }
    return nearest;
  };
  MarkerFactorOptions options;
  const std::vector<PoseGraphProblem::PosePrior> constant = scene.map.Read([&](const MapData& data) {
    return MarkerPosePriors(data, scene.keyframes, scene.landmarks, options);
  });
  options.prior_from_corners = true;
  const std::vector<PoseGraphProblem::PosePrior> all = scene.map.Read([&](const MapData& data) {
    return MarkerPosePriors(data, scene.keyframes, scene.landmarks, options);
  });
  ASSERT_EQ(all.size(), constant.size());
  ASSERT_GE(all.size(), 4u);
  double near_sides = std::numeric_limits<double>::infinity(), far_sides = 0.0;
  double near_sigma = 0.0, far_sigma = 0.0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    ASSERT_EQ(all[i].node, constant[i].node);
    const double sides = nearest_sides(all[i]);
    const double sigma = LeastCertainPositionSigma(all[i].information);
    // The options' 5 cm per marker is a floor; the constant prior is the floor alone.
    EXPECT_GT(sigma, LeastCertainPositionSigma(constant[i].information)) << all[i].node;
    // Corners with 0.3 px noise against the 1 px assumed: the error is well within 3 sigmas.
    const Rigid3 truth = scene.truth.keypoints.poses[all[i].node].cam_from_world.Inverse();
    EXPECT_LT((all[i].world_from_cam.translation - truth.translation).norm(), 3.0 * sigma);
    if (sides < near_sides) near_sides = sides, near_sigma = sigma;
    if (sides > far_sides) far_sides = sides, far_sigma = sigma;
  }
  ASSERT_GT(far_sides, 2.0 * near_sides);
  EXPECT_GT(far_sigma, near_sigma);

  const double limit = 0.5 * (near_sides + far_sides);
  options.max_prior_distance_sides = limit;
  const std::vector<PoseGraphProblem::PosePrior> near = scene.map.Read([&](const MapData& data) {
    return MarkerPosePriors(data, scene.keyframes, scene.landmarks, options);
  });
  EXPECT_LT(near.size(), all.size());
  EXPECT_GE(near.size(), 1u);
  for (const auto& prior : near) {
    EXPECT_LE(nearest_sides(prior), limit) << prior.node;
  }
}

}  // namespace
}  // namespace arucoslam
