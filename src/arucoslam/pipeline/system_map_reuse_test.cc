// Map reuse in the System: a map built on one pass over a synthetic scene is loaded into a
// new System that sees a second pass starting elsewhere (in the middle of the route, going
// back); it must localise, stay accurate and, in localisation-only mode, leave the map as is.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "arucoslam/geometry/umeyama.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/slam/synthetic_marker_scene.h"
#include "arucoslam/slam/synthetic_features.h"

namespace arucoslam {
namespace {

using test_scene::kSceneDt;
using test_scene::SceneCamera;
using test_scene::SceneDetections;
using test_scene::SceneMarkers;

// Route position t (any real number): sideways, weaving, slowly turning, metres.
Rigid3 WorldFromCam(double t) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.003 * t, Eigen::Vector3d::UnitY())),
                Eigen::Vector3d(0.03 * t, 0.2 * std::sin(t / 15.0), 0.003 * t));
}

struct Pass {
  std::vector<double> route;  // route position of each frame
  std::vector<FrameReport> reports;
  std::vector<StampedPose> trajectory;
  SystemStats stats;
  MapData map;
  bool world_aligned = false;
};

// Feeds the frames at `route` positions (timestamps kSceneDt apart) to a System, optionally
// started from `loaded`. The scene (points and descriptors) is the same for every pass.
// Frames [blackout_begin, blackout_end) have neither keypoints nor markers.
Pass RunPass(const std::vector<double>& route, bool markers, bool blocking,
             const MapData* loaded = nullptr, bool loaded_aligned = false,
             bool localize_only = false, std::uint32_t noise_seed = 1,
             std::size_t blackout_begin = 0, std::size_t blackout_end = 0) {
  SyntheticFeatureScene scene(SceneCamera());
  SystemOptions options;
  options.blocking = blocking;
  if (markers) options.marker_map = SceneMarkers();
  System system(SceneCamera(), options);
  if (loaded != nullptr) system.StartFromMap(*loaded, loaded_aligned, localize_only);
  std::mt19937 rng(noise_seed);
  Pass pass;
  pass.route = route;
  std::vector<int> truth;
  for (std::size_t i = 0; i < route.size(); ++i) {
    const Rigid3 cam_from_world = WorldFromCam(route[i]).Inverse();
    Frame frame = scene.MakeFrame(FrameId(i), kSceneDt * i, cam_from_world, &truth);
    std::vector<MarkerDetection> detections =
        markers ? SceneDetections(*options.marker_map, SceneCamera(), cam_from_world, rng) : std::vector<MarkerDetection>{};
    if (i >= blackout_begin && i < blackout_end) {
      frame.features = OrbFeatures();
      frame.ResetMatches();
      detections.clear();
    }
    pass.reports.push_back(system.ProcessFrame(std::move(frame), detections));
  }
  system.Finish();
  pass.trajectory = system.Trajectory();
  pass.stats = system.Stats();
  pass.map = system.map().Read([](const MapData& data) { return data; });
  pass.world_aligned = system.world_aligned();
  return pass;
}

std::vector<double> Route(double from, double to, double step) {
  std::vector<double> route;
  for (double t = from; step > 0 ? t <= to : t >= to; t += step) route.push_back(t);
  return route;
}

Eigen::Vector3d TruePosition(const Pass& pass, double timestamp_s) {
  return WorldFromCam(pass.route[static_cast<std::size_t>(std::lround(timestamp_s / kSceneDt))])
      .translation;
}

// truth_from_map: the Sim(3) that best maps a pass's estimated positions onto the truth.
Sim3 TruthFromMap(const Pass& pass) {
  std::vector<Eigen::Vector3d> estimated, truth;
  for (const StampedPose& pose : pass.trajectory) {
    estimated.push_back(pose.world_from_cam.translation);
    truth.push_back(TruePosition(pass, pose.timestamp_s));
  }
  const std::optional<Sim3> alignment =
      UmeyamaAlignment(estimated, truth, AlignmentKind::kSimilarity);
  EXPECT_TRUE(alignment.has_value());
  return alignment.value_or(Sim3());
}

// RMS position error of a pass's trajectory mapped by `truth_from_map`, metres.
double RmsError(const Pass& pass, const Sim3& truth_from_map) {
  double sum = 0.0;
  for (const StampedPose& pose : pass.trajectory) {
    sum += (truth_from_map * pose.world_from_cam.translation -
            TruePosition(pass, pose.timestamp_s)).squaredNorm();
  }
  return pass.trajectory.empty() ? 1e9 : std::sqrt(sum / pass.trajectory.size());
}

// Frames from the first pose on that have a keypoint (not marker-only) pose.
double LocalisedFraction(const Pass& pass, int* first_pose) {
  *first_pose = -1;
  int localised = 0;
  for (std::size_t i = 0; i < pass.reports.size(); ++i) {
    const FrameReport& report = pass.reports[i];
    const bool keypoint_pose = report.cam_from_world && !report.marker_pose;
    if (keypoint_pose && *first_pose < 0) *first_pose = static_cast<int>(i);
    if (keypoint_pose) ++localised;
  }
  if (*first_pose < 0) return 0.0;
  return static_cast<double>(localised) / (pass.reports.size() - *first_pose);
}

// Same keyframes with bit-identical poses, same points with bit-identical positions.
void ExpectSameGeometry(const MapData& before, const MapData& after) {
  ASSERT_EQ(after.NumKeyframes(), before.NumKeyframes());
  ASSERT_EQ(after.NumMapPoints(), before.NumMapPoints());
  for (const auto& [id, keyframe] : before.keyframes()) {
    const Keyframe* kept = after.FindKeyframe(id);
    ASSERT_NE(kept, nullptr) << id.value;
    EXPECT_EQ(kept->cam_from_world.translation, keyframe.cam_from_world.translation);
    EXPECT_EQ(kept->map_point_ids, keyframe.map_point_ids);
  }
  for (const auto& [id, point] : before.map_points()) {
    const MapPoint* kept = after.FindMapPoint(id);
    ASSERT_NE(kept, nullptr) << id.value;
    EXPECT_EQ(kept->p_in_world, point.p_in_world);
  }
}

TEST(SystemMapReuse, WorldAlignedMapLocalisesASecondPassFromMarkers) {
  const Pass first = RunPass(Route(0, 80, 1), /*markers=*/true, /*blocking=*/true);
  ASSERT_TRUE(first.world_aligned);
  // Second pass: starts in the middle of the route (t = 60) and drives back to t = 20.
  const Pass second = RunPass(Route(60, 20, -1), true, true, &first.map, true,
                              /*localize_only=*/true, /*noise_seed=*/2);
  int first_pose = -1;
  const double fraction = LocalisedFraction(second, &first_pose);
  EXPECT_EQ(first_pose, 0);  // the markers are in view from the first frame
  EXPECT_GE(fraction, 0.95);
  EXPECT_EQ(second.stats.num_initializations, 0);
  EXPECT_GE(second.stats.num_marker_relocalizations, 1);
  // In the world frame without any alignment: measured 4.0 mm RMS.
  EXPECT_LT(RmsError(second, Sim3()), 0.01);
  EXPECT_EQ(second.stats.num_keyframes_inserted, 0);
  EXPECT_EQ(second.stats.local_mapping_ms.Count(), 0u);
  EXPECT_EQ(second.map.CheckInvariants(), "");
  ExpectSameGeometry(first.map, second.map);
}

TEST(SystemMapReuse, KeypointMapLocalisesASecondPassFromKeyframeMatches) {
  const Pass first = RunPass(Route(0, 80, 1), /*markers=*/false, /*blocking=*/true);
  ASSERT_GE(first.trajectory.size(), 70u);
  const Sim3 truth_from_map = TruthFromMap(first);
  // Threaded: the mapping thread runs but gets no keyframe.
  const Pass second = RunPass(Route(60, 20, -1), false, /*blocking=*/false, &first.map, false,
                              /*localize_only=*/true, 2);
  int first_pose = -1;
  const double fraction = LocalisedFraction(second, &first_pose);
  ASSERT_GE(first_pose, 0) << "never localised";
  EXPECT_LE(first_pose, 3);
  EXPECT_GE(fraction, 0.95);
  EXPECT_GE(second.stats.num_map_relocalizations, 1);
  EXPECT_EQ(second.stats.num_initializations, 0);
  // In the first pass's map frame: the first pass's alignment to the truth fits the second
  // pass too (measured 1.5 mm RMS; bound 1% of the 2.4 m route, as for a single pass).
  EXPECT_LT(RmsError(second, truth_from_map), 0.024);
  EXPECT_EQ(second.stats.num_keyframes_inserted, 0);
  ExpectSameGeometry(first.map, second.map);
}

TEST(SystemMapReuse, LocaliseOnlyRelocalisesAfterABlackout) {
  const Pass first = RunPass(Route(0, 80, 1), false, true);
  const Sim3 truth_from_map = TruthFromMap(first);
  // Frames 15-24 of the second pass are black: tracking is lost, then must come back.
  const Pass second =
      RunPass(Route(60, 20, -1), false, true, &first.map, false, true, 2, 15, 25);
  EXPECT_GE(second.stats.num_losses, 1);
  // The first frame is localised from keyframe matches; after the blackout the tracker's
  // reference-keyframe search (or a relocalisation) takes the map back at once.
  EXPECT_GE(second.stats.num_map_relocalizations, 1);
  for (std::size_t i = 0; i < second.reports.size(); ++i) {
    const bool black = i >= 15 && i < 25;
    EXPECT_EQ(second.reports[i].cam_from_world.has_value(), !black) << i;
  }
  EXPECT_LT(RmsError(second, truth_from_map), 0.024);
  EXPECT_EQ(second.stats.num_keyframes_inserted, 0);
  EXPECT_EQ(second.stats.map_session.num_resets, 0);
  ExpectSameGeometry(first.map, second.map);
}

TEST(SystemMapReuse, LoadedMapIsExtendedWithoutLocaliseOnly) {
  const Pass first = RunPass(Route(0, 60, 1), false, true);
  const Sim3 truth_from_map = TruthFromMap(first);
  // Starts inside the mapped part (t = 40) and goes on past its end to t = 110.
  const Pass second = RunPass(Route(40, 110, 1), false, true, &first.map, false, false, 2);
  int first_pose = -1;
  EXPECT_GE(LocalisedFraction(second, &first_pose), 0.95);
  EXPECT_LE(first_pose, 3);
  EXPECT_EQ(second.stats.num_initializations, 0);
  EXPECT_GT(second.stats.num_keyframes_inserted, 0);
  EXPECT_GT(second.map.NumKeyframes(), first.map.NumKeyframes());
  EXPECT_EQ(second.map.CheckInvariants(), "");
  // Still the first pass's frame and scale beyond the old map (measured 2.1 mm RMS): bound
  // 1% of the 3.3 m driven by both passes.
  EXPECT_LT(RmsError(second, truth_from_map), 0.033);
}

TEST(SystemMapReuse, StartFromMapOnlyBeforeTheFirstFrame) {
  System system(SceneCamera());
  EXPECT_THROW(system.StartFromMap(MapData(), false, true), std::invalid_argument);
  SyntheticFeatureScene scene(SceneCamera());
  std::vector<int> truth;
  system.ProcessFrame(scene.MakeFrame(FrameId(0), 0.0, WorldFromCam(0).Inverse(), &truth));
  const Pass first = RunPass(Route(0, 30, 1), false, true);
  EXPECT_THROW(system.StartFromMap(first.map, false, true), std::logic_error);
}

}  // namespace
}  // namespace arucoslam
