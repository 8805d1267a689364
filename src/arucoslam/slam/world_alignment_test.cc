#include "arucoslam/slam/world_alignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/optim/marker_bundle_adjustment_synthetic.h"

namespace arucoslam {
namespace {

// The map frame of a monocular run: anything, at a third of the metric scale.
const Sim3 kMapFromWorld(
    0.37, Eigen::Quaterniond(Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.5, 0.8).normalized())),
    Eigen::Vector3d(2.0, -1.0, 0.5));

Rigid3 Noisy(const Rigid3& pose, double translation_m, double rotation_rad, std::mt19937& random) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Vector6d delta;
  for (int k = 0; k < 3; ++k) delta[k] = translation_m * normal(random);
  for (int k = 3; k < 6; ++k) delta[k] = rotation_rad * normal(random);
  return pose * Rigid3::Exp(delta);  // noise in the camera's own frame
}

// Anchors for every `step`-th pose of the synthetic corridor: the map pose is the truth moved
// into the map frame; the marker pose is the truth with 1 cm / 0.5 degree noise.
std::vector<WorldAnchor> Anchors(const std::vector<Rigid3>& true_cam_from_world, int step) {
  std::mt19937 random(3);
  std::vector<WorldAnchor> anchors;
  for (std::size_t i = 0; i < true_cam_from_world.size(); i += step) {
    WorldAnchor anchor;
    anchor.keyframe = KeyframeId(i);
    anchor.cam_from_map = kMapFromWorld.TransformPose(true_cam_from_world[i].Inverse()).Inverse();
    anchor.world_from_cam = Noisy(true_cam_from_world[i].Inverse(), 0.01, 0.009, random);
    anchors.push_back(anchor);
  }
  return anchors;
}

std::vector<Rigid3> CorridorPoses() {
  std::vector<Rigid3> poses;
  for (const auto& pose : MakeSyntheticMarkerScene({}).keypoints.poses) {
    poses.push_back(pose.cam_from_world);
  }
  return poses;
}

// Scale within 1% (the acceptance bound), rotation within 0.6 degrees, and every camera
// centre of `poses` carried to within `max_error_m` of its true position.
void ExpectRecovers(const WorldAlignment& alignment, const std::vector<Rigid3>& poses,
                    double max_error_m) {
  ASSERT_TRUE(alignment.success) << alignment.failure;
  const Sim3 identity = alignment.world_from_map * kMapFromWorld;
  EXPECT_NEAR(identity.scale, 1.0, 0.01);
  EXPECT_LT(RotationAngle(identity.rotation), 0.01);
  for (const Rigid3& cam_from_world : poses) {
    const Eigen::Vector3d centre = cam_from_world.Inverse().translation;
    EXPECT_LT((identity * centre - centre).norm(), max_error_m);
  }
}

TEST(WorldAlignmentTest, CentresOfACorridorGiveScaleWithinOnePercent) {
  const auto anchors = Anchors(CorridorPoses(), 2);
  const WorldAlignment alignment = EstimateWorldFromMap(anchors);
  ExpectRecovers(alignment, CorridorPoses(), 0.02);
  EXPECT_EQ(alignment.num_inliers, static_cast<int>(anchors.size()));
  EXPECT_LT(alignment.rms_m, 0.03);
}

TEST(WorldAlignmentTest, OneGrossOutlierIsFoundAndLeftOut) {
  auto anchors = Anchors(CorridorPoses(), 2);
  anchors[3].world_from_cam.translation += Eigen::Vector3d(0.0, 0.8, 0.3);
  const WorldAlignment alignment = EstimateWorldFromMap(anchors);
  ExpectRecovers(alignment, CorridorPoses(), 0.02);
  EXPECT_FALSE(alignment.inliers[3]);
  EXPECT_EQ(alignment.num_inliers, static_cast<int>(anchors.size()) - 1);
}

TEST(WorldAlignmentTest, AmbiguousPosesAreLeftOutByDefault) {
  auto anchors = Anchors(CorridorPoses(), 2);
  // Two ambiguous anchors carry IPPE's other solution: the camera mirrored about the marker.
  for (int i : {1, 4}) {
    anchors[i].ambiguous = true;
    anchors[i].world_from_cam =
        Rigid3(anchors[i].world_from_cam.rotation *
                   Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY())),
               anchors[i].world_from_cam.translation + Eigen::Vector3d(0.0, 0.6, 0.0));
  }
  const WorldAlignment alignment = EstimateWorldFromMap(anchors);
  ExpectRecovers(alignment, CorridorPoses(), 0.02);
  EXPECT_FALSE(alignment.inliers[1]);
  EXPECT_FALSE(alignment.inliers[4]);
}

TEST(WorldAlignmentTest, AnLShapedPathTakesItsRotationFromCentres) {
  std::vector<Rigid3> poses;
  for (int i = 0; i < 10; ++i) {
    const Eigen::Vector3d centre =
        i < 5 ? Eigen::Vector3d(0.6 * i, 0.0, 1.0) : Eigen::Vector3d(2.4, 0.6 * (i - 4), 1.0);
    poses.push_back(Rigid3(Eigen::Quaterniond::Identity(), centre).Inverse());
  }
  const WorldAlignment alignment = EstimateWorldFromMap(Anchors(poses, 1));
  ExpectRecovers(alignment, poses, 0.02);
  EXPECT_EQ(alignment.method, WorldAlignmentMethod::kCentres);
}

TEST(WorldAlignmentTest, StraightPathTakesItsRotationFromOrientations) {
  std::vector<Rigid3> poses;
  for (int i = 0; i < 8; ++i) {
    // Along world x, each camera turned differently: the centres alone leave the roll
    // about the line free.
    const Eigen::Quaterniond rotation(Eigen::AngleAxisd(0.2 * i, Eigen::Vector3d::UnitY()));
    poses.push_back(Rigid3(rotation, Eigen::Vector3d(0.5 * i, 1.0, 1.0)).Inverse());
  }
  const WorldAlignment alignment = EstimateWorldFromMap(Anchors(poses, 1));
  ExpectRecovers(alignment, poses, 0.03);
  EXPECT_EQ(alignment.method, WorldAlignmentMethod::kOrientationsAndCentres);
}

TEST(WorldAlignmentTest, TwoAnchorsSuffice) {
  const auto poses = CorridorPoses();
  const auto anchors = Anchors({poses.front(), poses.back()}, 1);
  // Orientation noise of two poses only: centres along the 6 m path within 4 cm.
  ExpectRecovers(EstimateWorldFromMap(anchors), poses, 0.04);
}

TEST(WorldAlignmentTest, SingleAnchorNeedsTheMarkerDepth) {
  const auto poses = CorridorPoses();
  auto anchors = Anchors({poses[5]}, 1);
  WorldAlignment alignment = EstimateWorldFromMap(anchors);
  EXPECT_FALSE(alignment.success);
  EXPECT_NE(alignment.failure.find("unobservable"), std::string::npos);
  // The marker 3.2 m away in metres is 3.2 * 0.37 map units away (to 0.5%).
  anchors[0].marker_depth_m = 3.2;
  anchors[0].marker_depth_in_map = 3.2 * 0.37 * 1.005;
  alignment = EstimateWorldFromMap(anchors);
  ASSERT_TRUE(alignment.success);
  EXPECT_EQ(alignment.method, WorldAlignmentMethod::kSingleAnchor);
  EXPECT_NEAR((alignment.world_from_map * kMapFromWorld).scale, 1.0, 0.01);
  // Position of the anchor itself exact up to the noise of its marker pose.
  EXPECT_LT((alignment.world_from_map * anchors[0].cam_from_map.Inverse().translation -
             poses[5].Inverse().translation)
                .norm(),
            0.05);
}

TEST(WorldAlignmentTest, NothingUsableFails) {
  EXPECT_FALSE(EstimateWorldFromMap({}).success);
  auto anchors = Anchors(CorridorPoses(), 5);
  for (auto& anchor : anchors) anchor.ambiguous = true;
  EXPECT_FALSE(EstimateWorldFromMap(anchors).success);
  WorldAlignmentOptions options;
  options.ambiguous_weight = 0.5;  // accepted when asked for
  EXPECT_TRUE(EstimateWorldFromMap(anchors, options).success);
}

TEST(WorldAlignmentTest, ApplyMovesKeyframesPointsAndMappedMarkers) {
  MapData map;
  const Rigid3 true_cam_from_world =
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())),
             Eigen::Vector3d(0.1, 0.2, 0.3));
  Keyframe keyframe;
  keyframe.cam_from_world = kMapFromWorld.TransformPose(true_cam_from_world.Inverse()).Inverse();
  const KeyframeId id = map.AddKeyframe(keyframe);
  MapPoint point;
  const Eigen::Vector3d p_in_world(1.0, 2.0, 5.0);
  point.p_in_world = kMapFromWorld * p_in_world;
  const MapPointId point_id = map.AddMapPoint(point);
  MarkerLandmarks markers;
  MarkerLandmark known, mapped;
  known.id = MarkerId(1);
  known.size = 0.2;
  known.fixed = true;
  known.world_from_marker.translation = Eigen::Vector3d(3, 0, 1);
  mapped = known;
  mapped.id = MarkerId(2);
  mapped.fixed = false;
  mapped.world_from_marker = kMapFromWorld.TransformPose(known.world_from_marker);
  markers.Add(known);
  markers.Add(mapped);

  ApplyWorldAlignment(kMapFromWorld.Inverse(), &map, &markers);
  const Rigid3 moved = map.FindKeyframe(id)->cam_from_world;
  EXPECT_LT((moved.translation - true_cam_from_world.translation).norm(), 1e-12);
  EXPECT_LT(RotationAngle(moved.rotation * true_cam_from_world.rotation.inverse()), 1e-12);
  EXPECT_LT((map.FindMapPoint(point_id)->p_in_world - p_in_world).norm(), 1e-12);
  EXPECT_EQ(markers.Find(MarkerId(1))->world_from_marker.translation, Eigen::Vector3d(3, 0, 1));
  EXPECT_LT(
      (markers.Find(MarkerId(2))->world_from_marker.translation - Eigen::Vector3d(3, 0, 1)).norm(),
      1e-12);
  EXPECT_EQ(map.CheckInvariants(), "");
}

// A merged part already in the world stays: its keyframes, and the points one of them sees.
TEST(WorldAlignmentTest, KeyframesThatStayAndTheirPointsDoNotMove) {
  MapData map;
  Keyframe keyframe;
  keyframe.features.keypoints.assign(2, cv::KeyPoint(10.0f, 10.0f, 31.0f));
  keyframe.cam_from_world.translation = Eigen::Vector3d(0.0, 0.0, 1.0);
  const KeyframeId moving = map.AddKeyframe(keyframe);
  keyframe.cam_from_world.translation = Eigen::Vector3d(5.0, 0.0, 1.0);
  const KeyframeId staying = map.AddKeyframe(keyframe);
  MapPoint point;
  point.p_in_world = Eigen::Vector3d(1.0, 2.0, 5.0);
  const MapPointId own = map.AddMapPoint(point);     // seen by the moving keyframe only
  const MapPointId shared = map.AddMapPoint(point);  // seen by both
  ASSERT_TRUE(map.AddObservation(moving, 0, own));
  ASSERT_TRUE(map.AddObservation(moving, 1, shared));
  ASSERT_TRUE(map.AddObservation(staying, 1, shared));
  const std::set<KeyframeId> stay = {staying};
  ApplyWorldAlignment(kMapFromWorld, &map, nullptr, &stay);
  const Rigid3 expected = kMapFromWorld.TransformPose(Rigid3(Eigen::Quaterniond::Identity(),
                                                             Eigen::Vector3d(0.0, 0.0, -1.0)));
  EXPECT_LT((map.FindKeyframe(moving)->cam_from_world.Inverse().translation -
             expected.translation).norm(), 1e-12);
  EXPECT_EQ(map.FindKeyframe(staying)->cam_from_world.translation, Eigen::Vector3d(5, 0, 1));
  EXPECT_LT((map.FindMapPoint(own)->p_in_world - kMapFromWorld * point.p_in_world).norm(), 1e-12);
  EXPECT_EQ(map.FindMapPoint(shared)->p_in_world, point.p_in_world);
}

// The pieces together on a monocular map at a third of the metric scale: camera poses from
// LocateCamera on the marker corners, the Sim(3) from them, then bundle adjustment with the
// markers fixed. The result is metric and in the world frame.
TEST(WorldAlignmentTest, LocatedCamerasAlignAndBundleAdjustmentMakesTheMapMetric) {
  SyntheticMarkerSceneOptions scene_options;
  scene_options.noise_px = 0.5;
  scene_options.corner_noise_px = 0.3;
  const MarkerBundleAdjustmentProblem truth = MakeSyntheticMarkerScene(scene_options);
  CameraModel camera;
  camera.width = scene_options.image_width;
  camera.height = scene_options.image_height;
  camera.fx = truth.keypoints.intrinsics.fx;
  camera.fy = truth.keypoints.intrinsics.fy;
  camera.cx = truth.keypoints.intrinsics.cx;
  camera.cy = truth.keypoints.intrinsics.cy;
  MarkerMap known;
  for (std::size_t m = 0; m < truth.markers.size(); ++m) {
    MarkerInfo info;
    info.id = static_cast<int>(m);
    info.size = truth.markers[m].size;
    info.world_from_marker = truth.markers[m].world_from_marker;
    known.markers[info.id] = info;
  }
  // The keypoint map: the truth in the map frame with 5 mm / 0.15 degree of drift per pose.
  MarkerBundleAdjustmentProblem problem = truth;
  std::mt19937 random(21);
  for (auto& pose : problem.keypoints.poses) {
    const Rigid3 map_from_cam = kMapFromWorld.TransformPose(pose.cam_from_world.Inverse());
    pose.cam_from_world = Noisy(map_from_cam, 0.005 * 0.37, 0.0026, random).Inverse();
  }
  for (auto& point : problem.keypoints.points) point.p_in_world = kMapFromWorld * point.p_in_world;

  std::vector<WorldAnchor> anchors;
  for (std::size_t pose = 0; pose < truth.keypoints.poses.size(); ++pose) {
    std::vector<MarkerDetection> detections;
    for (const auto& observation : truth.marker_observations) {
      if (observation.pose_index != pose) continue;
      MarkerDetection detection;
      detection.id = static_cast<int>(observation.marker_index);
      detection.corners = observation.corners_px;
      detections.push_back(detection);
    }
    const CameraLocation location = LocateCamera(detections, known, camera);
    if (!location.found) continue;
    WorldAnchor anchor;
    anchor.keyframe = KeyframeId(pose);
    anchor.cam_from_map = problem.keypoints.poses[pose].cam_from_world;
    anchor.world_from_cam = location.world_from_cam;
    anchor.ambiguous = location.quality.ambiguous;
    anchors.push_back(anchor);
  }
  ASSERT_GE(anchors.size(), 5u);
  const WorldAlignment alignment = EstimateWorldFromMap(anchors);
  ASSERT_TRUE(alignment.success) << alignment.failure;
  EXPECT_NEAR((alignment.world_from_map * kMapFromWorld).scale, 1.0, 0.01);

  for (auto& pose : problem.keypoints.poses) {
    pose.cam_from_world =
        alignment.world_from_map.TransformPose(pose.cam_from_world.Inverse()).Inverse();
  }
  for (auto& point : problem.keypoints.points) {
    point.p_in_world = alignment.world_from_map * point.p_in_world;
  }
  MarkerBundleAdjustmentOptions options;
  options.solver.max_iterations = 50;
  const MarkerBundleAdjustmentSummary summary = SolveMarkerBundleAdjustment(options, &problem);
  ASSERT_TRUE(summary.success) << summary.message;
  double worst = 0.0;
  for (std::size_t i = 0; i < truth.keypoints.poses.size(); ++i) {
    worst = std::max(worst, (problem.keypoints.poses[i].cam_from_world.Inverse().translation -
                             truth.keypoints.poses[i].cam_from_world.Inverse().translation)
                                .norm());
  }
  EXPECT_LT(worst, 0.02) << summary.BriefReport();
  const auto centre = [](const MarkerBundleAdjustmentProblem& p, std::size_t i) {
    return p.keypoints.poses[i].cam_from_world.Inverse().translation;
  };
  const std::size_t last = truth.keypoints.poses.size() - 1;
  EXPECT_NEAR((centre(problem, last) - centre(problem, 0)).norm() /
                  (centre(truth, last) - centre(truth, 0)).norm(),
              1.0, 0.01);
}

}  // namespace
}  // namespace arucoslam
