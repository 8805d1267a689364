#include "arucoslam/slam/marker_mapper.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <utility>

#include "arucoslam/geometry/sim3.h"
#include "arucoslam/optim/marker_bundle_adjustment_synthetic.h"

namespace arucoslam {
namespace {

CameraModel SceneCamera(const MarkerBundleAdjustmentProblem& scene,
                        const SyntheticMarkerSceneOptions& options) {
  CameraModel camera;
  camera.width = options.image_width;
  camera.height = options.image_height;
  camera.fx = scene.keypoints.intrinsics.fx;
  camera.fy = scene.keypoints.intrinsics.fy;
  camera.cx = scene.keypoints.intrinsics.cx;
  camera.cy = scene.keypoints.intrinsics.cy;
  return camera;
}

// A map as a monocular SLAM with a slightly wrong scale and some drift would hold it, and
// the marker observations of each keyframe.
struct MappedScene {
  SyntheticMarkerSceneOptions options;
  MarkerBundleAdjustmentProblem truth;
  CameraModel camera;
  MapData map;
  std::vector<KeyframeId> keyframes;
  std::vector<std::vector<MarkerObservation>> markers;  // per keyframe
};

void Build(MappedScene& scene, const Sim3& estimate_from_true, double drift,
           double corner_noise_px = 0.3) {
  scene.options.noise_px = 0.5;
  scene.options.corner_noise_px = corner_noise_px;
  scene.truth = MakeSyntheticMarkerScene(scene.options);
  scene.camera = SceneCamera(scene.truth, scene.options);
  const PinholeIntrinsics& k = scene.truth.keypoints.intrinsics;
  std::mt19937 random(9);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<MapPointId> points;
  for (const auto& point : scene.truth.keypoints.points) {
    MapPoint map_point;
    map_point.p_in_world = estimate_from_true * point.p_in_world;
    points.push_back(scene.map.AddMapPoint(map_point));
  }
  for (std::size_t i = 0; i < scene.truth.keypoints.poses.size(); ++i) {
    Keyframe keyframe;
    keyframe.camera = scene.camera;
    keyframe.features.pyramid = ScalePyramid::Make(8, 1.2);
    Vector6d delta;
    for (int c = 0; c < 3; ++c) delta[c] = drift * normal(random);
    for (int c = 3; c < 6; ++c) delta[c] = 0.5 * drift * normal(random);
    const Rigid3 world_from_cam =
        estimate_from_true.TransformPose(scene.truth.keypoints.poses[i].cam_from_world.Inverse());
    keyframe.cam_from_world = Rigid3::Exp(delta) * world_from_cam.Inverse();
    for (const auto& observation : scene.truth.keypoints.observations) {
      if (observation.pose_index != i) continue;
      cv::KeyPoint keypoint(observation.pixel.x(), observation.pixel.y(), 31.0f);
      keypoint.octave = 0;
      keyframe.features.keypoints.push_back(keypoint);
      keyframe.features.undistorted.push_back(Eigen::Vector2d(
          (observation.pixel.x() - k.cx) / k.fx, (observation.pixel.y() - k.cy) / k.fy));
      keyframe.map_point_ids.push_back(points[observation.point_index]);
    }
    keyframe.features.descriptors =
        cv::Mat::zeros(static_cast<int>(keyframe.features.size()), kOrbDescriptorBytes, CV_8U);
    scene.keyframes.push_back(scene.map.AddKeyframe(std::move(keyframe)));
    std::vector<MarkerObservation> seen;
    for (const auto& observation : scene.truth.marker_observations) {
      if (observation.pose_index != i) continue;
      seen.push_back(
          {MarkerId(static_cast<int>(observation.marker_index)), observation.corners_px});
    }
    scene.markers.push_back(seen);
  }
}

// The known map: the scene's first `count` markers (default: only marker 0), fixed.
MarkerMap KnownMap(const MarkerBundleAdjustmentProblem& truth, std::size_t count = 1) {
  MarkerMap map;
  for (std::size_t m = 0; m < count && m < truth.markers.size(); ++m) {
    MarkerInfo info;
    info.id = static_cast<int>(m);
    info.size = truth.markers[m].size;
    info.world_from_marker = truth.markers[m].world_from_marker;
    info.fixed = true;
    map.markers[info.id] = info;
  }
  return map;
}

double PositionError(const MarkerLandmark& landmark, const MarkerBundleAdjustmentProblem& truth) {
  return (landmark.world_from_marker.translation -
          truth.markers[landmark.id.value].world_from_marker.translation)
      .norm();
}

void AddAll(MappedScene& scene, MarkerMapper& mapper) {
  for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
    mapper.AddKeyframe(scene.keyframes[i],
                       scene.map.FindKeyframe(scene.keyframes[i])->cam_from_world, scene.camera,
                       scene.markers[i]);
  }
}

TEST(MarkerMapperTest, AllButOneMarkerUnknownAreMappedWithinThreeCentimetres) {
  MappedScene scene;
  Build(scene,
        Sim3(1.02, Eigen::Quaterniond(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ())),
             Eigen::Vector3d(0.03, -0.02, 0.01)),
        0.004);
  MarkerMapper mapper(KnownMap(scene.truth));
  AddAll(scene, mapper);
  EXPECT_EQ(mapper.NumPending(), 0);
  ASSERT_EQ(mapper.landmarks().size(), scene.truth.markers.size());
  double worst_initial = 0.0;
  for (const auto& [id, landmark] : mapper.landmarks().landmarks()) {
    worst_initial = std::max(worst_initial, PositionError(landmark, scene.truth));
  }
  // Initialised from drifted poses: decimetres off, not metres.
  EXPECT_LT(worst_initial, 0.5);
  const MarkerBundleAdjustmentSummary summary = mapper.Refine(&scene.map);
  ASSERT_TRUE(summary.success) << summary.message;
  for (const auto& [id, landmark] : mapper.landmarks().landmarks()) {
    EXPECT_LT(PositionError(landmark, scene.truth), 0.03) << "marker " << id.value;
    const Eigen::Quaterniond& truth = scene.truth.markers[id.value].world_from_marker.rotation;
    EXPECT_LT(RotationAngle(landmark.world_from_marker.rotation * truth.inverse()), 0.05)
        << "marker " << id.value;
  }
  EXPECT_GT(worst_initial, 0.03);  // the refinement is what brought them in
  const MarkerMap output = mapper.ToMarkerMap();
  ASSERT_EQ(output.markers.size(), scene.truth.markers.size());
  EXPECT_TRUE(output.markers.at(0).fixed);
  EXPECT_EQ(output.markers.at(0).world_from_marker.translation,
            scene.truth.markers[0].world_from_marker.translation);
  for (std::size_t m = 1; m < scene.truth.markers.size(); ++m) {
    EXPECT_FALSE(output.markers.at(static_cast<int>(m)).fixed);
    EXPECT_DOUBLE_EQ(output.markers.at(static_cast<int>(m)).size, scene.options.marker_size_m);
  }
  EXPECT_EQ(scene.map.CheckInvariants(), "");
}

// Keyframe camera centres against the truth, metres (RMS).
double KeyframeCentreRmse(const MappedScene& scene) {
  double sum = 0.0;
  for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
    const Eigen::Vector3d estimate =
        scene.map.FindKeyframe(scene.keyframes[i])->cam_from_world.Inverse().translation;
    const Eigen::Vector3d truth =
        scene.truth.keypoints.poses[i].cam_from_world.Inverse().translation;
    sum += (estimate - truth).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(scene.keyframes.size()));
}

// The whole-map adjustment a System runs when a map is closed and at the end of a run: every
// marker known and fixed, the map 4% too large, turned and shifted as a monocular map aligned
// from a few distant marker views would be.
TEST(MarkerMapperTest, WithEveryMarkerKnownRefinePullsAMisalignedMapOntoTheWorld) {
  MappedScene scene;
  Build(scene,
        Sim3(1.04, Eigen::Quaterniond(Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitY())),
             Eigen::Vector3d(0.10, -0.05, 0.08)),
        0.004);
  MarkerMapper mapper(KnownMap(scene.truth, scene.truth.markers.size()));
  AddAll(scene, mapper);
  const double before_m = KeyframeCentreRmse(scene);
  const MarkerBundleAdjustmentSummary summary = mapper.Refine(&scene.map);
  ASSERT_TRUE(summary.success) << summary.message;
  const double after_m = KeyframeCentreRmse(scene);
  // Measured: 0.270 m before, 2.2 mm after.
  EXPECT_GT(before_m, 0.1);
  EXPECT_LT(after_m, 0.01);
  for (const auto& [id, landmark] : mapper.landmarks().landmarks()) {
    EXPECT_EQ(landmark.world_from_marker.translation,
              scene.truth.markers[id.value].world_from_marker.translation);
  }
  EXPECT_EQ(scene.map.CheckInvariants(), "");
}

// Keyframe camera heights against the truth, metres (RMS).
double KeyframeHeightRmse(const MappedScene& scene) {
  double sum = 0.0;
  for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
    const double estimate =
        scene.map.FindKeyframe(scene.keyframes[i])->cam_from_world.Inverse().translation.z();
    const double truth = scene.truth.keypoints.poses[i].cam_from_world.Inverse().translation.z();
    sum += (estimate - truth) * (estimate - truth);
  }
  return std::sqrt(sum / static_cast<double>(scene.keyframes.size()));
}

// A ground vehicle's map (camera at 1 m, level), one known marker near the start, a long
// path with few noisy points: with MarkerMapperOptions::ground_plane_prior the whole-map
// adjustment holds the far keyframes at the camera's height.
TEST(MarkerMapperTest, GroundPlanePriorHoldsTheKeyframesOfAGroundVehicle) {
  const auto run = [](bool ground) {
    MappedScene scene;
    scene.options.height_wobble_m = 0.0;
    scene.options.num_markers = 1;
    scene.options.path_length_m = 12.0;
    scene.options.num_poses = 30;
    scene.options.num_points = 120;
    Build(scene,
          Sim3(1.0, Eigen::Quaterniond(Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitY())),
               Eigen::Vector3d::Zero()),
          0.01);
    MarkerMapperOptions options;
    if (ground) options.ground_plane_prior = GroundPlanePriorOptions{};
    MarkerMapper mapper(KnownMap(scene.truth), options);
    AddAll(scene, mapper);
    const MarkerBundleAdjustmentSummary summary = mapper.Refine(&scene.map);
    EXPECT_TRUE(summary.success) << summary.message;
    EXPECT_EQ(summary.ground_plane.has_value(), ground);
    if (summary.ground_plane) EXPECT_NEAR(summary.ground_plane->height_m, 1.0, 0.01);
    return KeyframeHeightRmse(scene);
  };
  const double free_m = run(false);
  const double held_m = run(true);
  std::printf("keyframe height RMS: %.4f m without the prior, %.4f m with it\n", free_m, held_m);
  EXPECT_LT(held_m, 0.005);
  EXPECT_LT(held_m, 0.5 * free_m);
}

TEST(MarkerMapperTest, AmbiguousViewsAreMappedOnceEnoughAgree) {
  MappedScene scene;
  Build(scene, Sim3(), 0.0, 0.0);  // exact poses and corners
  MarkerMapperOptions options;
  options.marker_pose.ambiguity_ratio = 1e-6;  // every single view counts as ambiguous
  MarkerMapper mapper(KnownMap(scene.truth), options);
  std::map<MarkerId, int> views;
  for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
    const auto initialised = mapper.AddKeyframe(
        scene.keyframes[i], scene.map.FindKeyframe(scene.keyframes[i])->cam_from_world,
        scene.camera, scene.markers[i]);
    for (const auto& observation : scene.markers[i]) ++views[observation.marker_id];
    for (const MarkerId id : initialised) {
      EXPECT_GE(views[id], options.min_consistent_views) << "marker " << id.value;
    }
    for (const auto& [id, count] : views) {
      if (count < options.min_consistent_views) {
        EXPECT_EQ(mapper.landmarks().Contains(id), id.value == 0) << "marker " << id.value;
      }
    }
  }
  EXPECT_EQ(mapper.NumPending(), 0);
  // Positions from IPPE are good to millimetres with exact corners. Orientation from three
  // close views of a small, distant marker is weak (IPPE's rotation of a 22 px marker at
  // 6 m can be 0.85 rad off at 0.23 px RMS); bundle adjustment over all views fixes it
  // (see the test above, 0.05 rad).
  for (const auto& [id, landmark] : mapper.landmarks().landmarks()) {
    EXPECT_LT(PositionError(landmark, scene.truth), 0.01) << "marker " << id.value;
  }
}

TEST(MarkerMapperTest, RefineMarkersAloneFitsTheRecordedPoses) {
  MappedScene scene;
  Build(scene, Sim3(), 0.0);  // exact poses, 0.3 px corner noise
  MarkerMapper mapper(KnownMap(scene.truth));
  AddAll(scene, mapper);
  double worst_initial = 0.0;
  for (const auto& [id, landmark] : mapper.landmarks().landmarks()) {
    worst_initial = std::max(worst_initial, PositionError(landmark, scene.truth));
  }
  const auto summary = mapper.RefineMarkers();
  ASSERT_TRUE(summary.success) << summary.message;
  EXPECT_LT(summary.final_marker_rms_px, summary.initial_marker_rms_px);
  double worst = 0.0;
  for (const auto& [id, landmark] : mapper.landmarks().landmarks()) {
    worst = std::max(worst, PositionError(landmark, scene.truth));
  }
  EXPECT_LT(worst, 0.03);
  EXPECT_LT(worst, worst_initial);  // all views together beat the first one
  // Forgetting every keyframe leaves markers without observations.
  for (const KeyframeId id : scene.keyframes) mapper.EraseKeyframe(id);
  for (const auto& [id, landmark] : mapper.landmarks().landmarks()) {
    EXPECT_TRUE(landmark.observations.empty());
  }
}

// Frames posed by markers alone (no keypoint map): their views map the unknown markers, a
// frame where one was taken already adds nothing, and the adjustment of markers and views
// brings the markers closer.
TEST(MarkerMapperTest, MarkerViewsMapUnknownMarkersWithoutKeyframes) {
  MappedScene scene;
  Build(scene, Sim3(), 0.003);  // view poses a few millimetres off, as located by markers
  MarkerMapper mapper(KnownMap(scene.truth));
  std::vector<MarkerId> initialised;
  int taken = 0;
  for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
    const Rigid3& pose = scene.map.FindKeyframe(scene.keyframes[i])->cam_from_world;
    if (mapper.AddMarkerView(pose, scene.camera, scene.markers[i], &initialised)) ++taken;
    // The same place again is not a new view.
    EXPECT_FALSE(mapper.AddMarkerView(pose, scene.camera, scene.markers[i], &initialised));
  }
  EXPECT_GT(taken, static_cast<int>(scene.keyframes.size()) / 2);
  EXPECT_EQ(mapper.NumMarkerViews(), taken);
  EXPECT_EQ(initialised.size() + 1, scene.truth.markers.size());
  ASSERT_EQ(mapper.landmarks().size(), scene.truth.markers.size());
  for (const auto& [id, landmark] : mapper.landmarks().landmarks()) {
    EXPECT_TRUE(landmark.observations.empty());  // no keyframe saw it
    EXPECT_GE(mapper.NumViews(id), 2) << "marker " << id.value;
  }
  double worst_initial = 0.0;
  for (const auto& [id, landmark] : mapper.landmarks().landmarks()) {
    worst_initial = std::max(worst_initial, PositionError(landmark, scene.truth));
  }
  const auto summary = mapper.RefineMarkers();
  ASSERT_TRUE(summary.success) << summary.message;
  double worst = 0.0;
  for (const auto& [id, landmark] : mapper.landmarks().landmarks()) {
    worst = std::max(worst, PositionError(landmark, scene.truth));
  }
  std::printf("markers mapped from marker views: worst %.4f m, %.4f m before the refinement\n",
              worst, worst_initial);
  // Markers up to 10 m away seen from poses a few millimetres and milliradians off.
  EXPECT_LT(worst, 0.05);
  EXPECT_LT(worst, 0.7 * worst_initial);  // all views together beat the first ones
  // A frame that sees only fixed markers maps nothing: it is not taken.
  MarkerMapper all_known(KnownMap(scene.truth, scene.truth.markers.size()));
  EXPECT_FALSE(all_known.AddMarkerView(scene.map.FindKeyframe(scene.keyframes[0])->cam_from_world,
                                       scene.camera, scene.markers[0], &initialised));
}

// A mapped marker left in the wrong orientation (a wrong IPPE branch) is turned back by
// RefineMarkers once its views explain another orientation clearly better.
TEST(MarkerMapperTest, RefineMarkersTurnsAMarkerOutOfAWrongOrientation) {
  MappedScene scene;
  Build(scene, Sim3(), 0.0);
  MarkerMapper mapper(KnownMap(scene.truth));
  AddAll(scene, mapper);
  const MarkerId wrong(1);
  const MarkerLandmark* landmark = mapper.landmarks().Find(wrong);
  ASSERT_NE(landmark, nullptr);
  const Rigid3 turned(landmark->world_from_marker.rotation *
                          Eigen::Quaterniond(Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitX())),
                      landmark->world_from_marker.translation);
  mapper.mutable_landmarks()->SetPose(wrong, turned);
  ASSERT_TRUE(mapper.RefineMarkers().success);
  const Eigen::Quaterniond& truth = scene.truth.markers[wrong.value].world_from_marker.rotation;
  EXPECT_LT(
      RotationAngle(mapper.landmarks().Find(wrong)->world_from_marker.rotation * truth.inverse()),
      0.05);
  EXPECT_LT(PositionError(*mapper.landmarks().Find(wrong), scene.truth), 0.01);
}

// With no marker known, the largest marker of the first detections becomes the world's
// origin, once, and only with a size for unknown markers.
TEST(MarkerMapperTest, AdoptsTheLargestMarkerAsTheWorldOrigin) {
  MappedScene scene;
  Build(scene, Sim3(), 0.0);
  std::vector<MarkerDetection> detections;
  for (const MarkerObservation& observation : scene.markers[0]) {
    detections.push_back({observation.marker_id.value, observation.corners_px});
  }
  ASSERT_GE(detections.size(), 2u);
  MarkerMapper unsized(MarkerMap{});
  EXPECT_FALSE(unsized.AdoptWorldOrigin(detections, scene.camera));
  MarkerMapperOptions options;
  options.unknown_marker_size_m = scene.options.marker_size_m;
  EXPECT_FALSE(MarkerMapper(KnownMap(scene.truth), options)
                   .AdoptWorldOrigin(detections, scene.camera));  // a marker is known
  MarkerMapper mapper(MarkerMap{}, options);
  ASSERT_TRUE(mapper.AdoptWorldOrigin(detections, scene.camera));
  EXPECT_FALSE(mapper.AdoptWorldOrigin(detections, scene.camera));  // once
  ASSERT_EQ(mapper.landmarks().size(), 1u);
  const MarkerLandmark& origin = mapper.landmarks().landmarks().begin()->second;
  EXPECT_TRUE(origin.fixed);
  EXPECT_LT(origin.world_from_marker.translation.norm(), 1e-12);
  // The nearest marker of the first view covers the most pixels.
  const Rigid3& cam_from_world = scene.truth.keypoints.poses[0].cam_from_world;
  double nearest = 1e9;
  int nearest_id = -1;
  for (const MarkerDetection& detection : detections) {
    const double distance =
        (cam_from_world * scene.truth.markers[detection.id].world_from_marker.translation).norm();
    if (distance < nearest) {
      nearest = distance;
      nearest_id = detection.id;
    }
  }
  EXPECT_EQ(origin.id.value, nearest_id);
}

TEST(MarkerMapperTest, WithoutAnySizeUnknownMarkersAreNotMapped) {
  MappedScene scene;
  Build(scene, Sim3(), 0.0);
  MarkerMapper mapper(MarkerMap{});
  AddAll(scene, mapper);
  EXPECT_TRUE(mapper.landmarks().empty());
  MarkerMapperOptions options;
  options.unknown_marker_size_m = scene.options.marker_size_m;
  MarkerMapper sized(MarkerMap{}, options);
  AddAll(scene, sized);
  EXPECT_EQ(sized.landmarks().size(), scene.truth.markers.size());
}

TEST(MarkerMapperTest, FalseDetectionsAreNotMapped) {
  MappedScene scene;
  Build(scene, Sim3(), 0.0);
  // Id 33 is detected once, at marker 1's corners; id 34 in three keyframes, each time at the
  // corners of another marker (metres apart): no place where three views agree.
  std::vector<std::pair<std::size_t, MarkerObservation>> seen;  // (keyframe, observation)
  for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
    for (const MarkerObservation& observation : scene.markers[i]) {
      if (observation.marker_id.value != 0) seen.push_back({i, observation});
    }
  }
  ASSERT_GE(seen.size(), 5u);
  const auto add_false = [&](std::size_t k, int id) {
    MarkerObservation fake = seen[k].second;
    fake.marker_id = MarkerId(id);
    scene.markers[seen[k].first].push_back(fake);
    return seen[k].second.marker_id;
  };
  add_false(0, 33);
  std::set<std::size_t> keyframes;
  std::set<MarkerId> places;
  for (std::size_t k = 1; k < seen.size() && places.size() < 3; ++k) {
    if (keyframes.count(seen[k].first) || places.count(seen[k].second.marker_id)) continue;
    keyframes.insert(seen[k].first);
    places.insert(add_false(k, 34));
  }
  ASSERT_EQ(places.size(), 3u);
  MarkerMapper mapper(KnownMap(scene.truth));
  AddAll(scene, mapper);
  EXPECT_FALSE(mapper.landmarks().Contains(MarkerId(33)));
  EXPECT_FALSE(mapper.landmarks().Contains(MarkerId(34)));
  const MarkerMap output = mapper.ToMarkerMap();
  EXPECT_EQ(output.markers.count(33), 0u);
  EXPECT_EQ(output.markers.count(34), 0u);
  // The real markers are all mapped.
  EXPECT_EQ(output.markers.size(), scene.truth.markers.size());
}

TEST(MarkerMapperTest, AKeyframeKeepsOnlyDetectionsOfMarkersItCouldHaveSeen) {
  // A known marker on a wall facing +y at x = 11.8 m; a camera 1.5 m from the wall looking
  // along -x passes it. Ahead of it the marker is readable; beside the camera (out of its
  // view) a detection with that id is a misread, and so is one seen from behind the wall.
  MarkerMap known;
  MarkerInfo info;
  info.id = 17;
  info.size = 0.2;
  Eigen::Matrix3d axes;  // marker x along -x, y along +z, its normal along +y
  axes.col(0) = -Eigen::Vector3d::UnitX();
  axes.col(1) = Eigen::Vector3d::UnitZ();
  axes.col(2) = Eigen::Vector3d::UnitY();
  info.world_from_marker = Rigid3(Eigen::Quaterniond(axes), Eigen::Vector3d(11.8, 0.0, 0.6));
  known.markers[info.id] = info;
  const CameraModel camera = PinholeCamera(640, 480, 460.0);
  Eigen::Matrix3d look_west;  // camera x = world +y, y = -world z, z = -world x
  look_west.col(0) = Eigen::Vector3d::UnitY();
  look_west.col(1) = -Eigen::Vector3d::UnitZ();
  look_west.col(2) = -Eigen::Vector3d::UnitX();
  auto cam_at = [&](double x, double y) {
    return Rigid3(Eigen::Quaterniond(look_west), Eigen::Vector3d(x, y, 0.6)).Inverse();
  };
  MarkerObservation sliver;
  sliver.marker_id = MarkerId{17};
  sliver.corners_px = {Eigen::Vector2d(300, 230), Eigen::Vector2d(304, 230),
                       Eigen::Vector2d(304, 247), Eigen::Vector2d(300, 247)};
  MarkerMapperOptions options;
  options.map_unknown = false;
  MarkerMapper mapper(known, options);
  mapper.AddKeyframe(KeyframeId{1}, cam_at(16.0, 1.5), camera, {sliver});   // ahead: kept
  mapper.AddKeyframe(KeyframeId{2}, cam_at(12.1, 1.5), camera, {sliver});   // beside: not
  mapper.AddKeyframe(KeyframeId{3}, cam_at(16.0, -1.5), camera, {sliver});  // behind: not
  const MarkerLandmark* landmark = mapper.landmarks().Find(MarkerId{17});
  ASSERT_NE(landmark, nullptr);
  EXPECT_EQ(landmark->observations.size(), 1u);
  EXPECT_EQ(landmark->observations.count(KeyframeId{1}), 1u);
  // Keyframe 1 sees the marker 70 degrees from its normal: a 60-degree limit drops it too.
  options.max_view_angle_deg = 60.0;
  MarkerMapper strict(known, options);
  strict.AddKeyframe(KeyframeId{1}, cam_at(16.0, 1.5), camera, {sliver});
  ASSERT_NE(strict.landmarks().Find(MarkerId{17}), nullptr);
  EXPECT_TRUE(strict.landmarks().Find(MarkerId{17})->observations.empty());
}

TEST(MarkerMapperTest, ADetectionWhosePoseNoDriftExplainsIsAMisread) {
  // Two known markers on a wall facing +y: 17 at x = 11.8 m, 13 at x = 7.0 m. A camera at
  // x = 12.45 m looking along -x sees 13 ahead; a misread of 13's pattern as 17 keeps 13's
  // corners, which put the camera about 5 m in front of 17, where no drift explains it.
  Eigen::Matrix3d axes;  // marker x along -x, y along +z, its normal along +y
  axes.col(0) = -Eigen::Vector3d::UnitX();
  axes.col(1) = Eigen::Vector3d::UnitZ();
  axes.col(2) = Eigen::Vector3d::UnitY();
  MarkerMap known;
  for (const auto& [id, x] : {std::pair{17, 11.8}, std::pair{13, 7.0}}) {
    MarkerInfo info;
    info.id = id;
    info.size = 0.2;
    info.world_from_marker = Rigid3(Eigen::Quaterniond(axes), Eigen::Vector3d(x, 0.0, 0.6));
    known.markers[id] = info;
  }
  const CameraModel camera = PinholeCamera(640, 480, 460.0);
  Eigen::Matrix3d look_west;  // camera x = world +y, y = -world z, z = -world x
  look_west.col(0) = Eigen::Vector3d::UnitY();
  look_west.col(1) = -Eigen::Vector3d::UnitZ();
  look_west.col(2) = -Eigen::Vector3d::UnitX();
  const Rigid3 true_cam_from_world =
      Rigid3(Eigen::Quaterniond(look_west), Eigen::Vector3d(12.45, 1.52, 0.6)).Inverse();
  MarkerObservation seen_13;
  seen_13.marker_id = MarkerId{13};
  const std::array<Eigen::Vector3d, 4> corners = SquareCorners(0.2);
  for (int i = 0; i < 4; ++i) {
    const std::optional<Eigen::Vector2d> pixel =
        camera.Project(true_cam_from_world * (known.markers.at(13).world_from_marker * corners[i]));
    ASSERT_TRUE(pixel.has_value());
    seen_13.corners_px[i] = *pixel;
  }
  MarkerObservation misread = seen_13;
  misread.marker_id = MarkerId{17};
  // The keyframe's pose has drifted 22 cm: the true detection still agrees with it.
  const Rigid3 drifted =
      Rigid3(Eigen::Quaterniond(look_west), Eigen::Vector3d(12.65, 1.62, 0.6)).Inverse();
  MarkerMapperOptions options;
  options.map_unknown = false;
  MarkerMapper mapper(known, options);
  mapper.AddKeyframe(KeyframeId{1}, drifted, camera, {seen_13, misread});
  EXPECT_EQ(mapper.landmarks().Find(MarkerId{13})->observations.count(KeyframeId{1}), 1u);
  EXPECT_TRUE(mapper.landmarks().Find(MarkerId{17})->observations.empty());
  // Retired with its map, the keyframe's record keeps its true view only.
  mapper.CloseMap();
  EXPECT_EQ(mapper.NumRetiredViews(), 1);
  // Without the test (any offset allowed) the misread joins marker 17's observations.
  options.max_detection_offset_ratio = 1e6;
  MarkerMapper lenient(known, options);
  lenient.AddKeyframe(KeyframeId{1}, drifted, camera, {seen_13, misread});
  EXPECT_EQ(lenient.landmarks().Find(MarkerId{17})->observations.count(KeyframeId{1}), 1u);
  lenient.CloseMap();
  EXPECT_EQ(lenient.NumRetiredViews(), 2);
}
}  // namespace
}  // namespace arucoslam
