#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <random>

#include "arucoslam/geometry/umeyama.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/slam/synthetic_marker_scene.h"
#include "arucoslam/slam/synthetic_features.h"

namespace arucoslam {
namespace {

using test_scene::kSceneDt;
using test_scene::SceneAbsoluteRmse;
using test_scene::SceneCamera;
using test_scene::SceneDetections;
using test_scene::SceneMarkers;
using test_scene::SceneWorldFromCam;

struct MarkerRun {
  std::vector<StampedPose> trajectory;
  MarkerMap marker_map;  // System::MarkerMapOutput
  std::vector<FrameReport> reports;
  SystemStats stats;
  bool aligned = false;
  std::string invariants;
};

// Frames [blackout_begin, blackout_end) have neither keypoints nor markers. Every wall
// marker is detected; the System knows `known` (default: all of them). With `hide_known`,
// the known markers are not detected after the blackout. `edit` may change frame t's
// detections (false ones).
using DetectionEdit = std::function<void(int t, std::vector<MarkerDetection>* detections)>;
MarkerRun RunWithMarkers(bool blocking, int num_frames, int blackout_begin = -1,
                         int blackout_end = -1, std::optional<MarkerMap> known = std::nullopt,
                         int min_locating_marker_keyframes = 3, bool hide_known = false,
                         const DetectionEdit& edit = {}) {
  const CameraModel camera = SceneCamera();
  SyntheticFeatureScene scene(camera);
  SystemOptions options;
  options.blocking = blocking;
  options.marker_map = known ? *known : SceneMarkers();
  options.min_locating_marker_keyframes = min_locating_marker_keyframes;
  // The tests were measured with a keyframe allowed on every frame; with the default spacing
  // of 4 frames the mapped markers of this 120-frame clip get their third keyframe view only
  // after frame 100 (MappedMarkersLocateFramesWhereNoKnownMarkerIsSeen then locates none).
  options.keyframes.min_frames_between = 0;
  const MarkerMap wall = SceneMarkers();
  System system(camera, options);
  std::mt19937 rng(7);
  MarkerRun run;
  std::vector<int> truth;
  for (int t = 0; t < num_frames; ++t) {
    const Rigid3 cam_from_world = SceneWorldFromCam(t).Inverse();
    Frame frame = scene.MakeFrame(FrameId(t), kSceneDt * t, cam_from_world, &truth);
    std::vector<MarkerDetection> detections =
        SceneDetections(wall, camera, cam_from_world, rng);
    if (hide_known && t >= blackout_end) {
      std::erase_if(detections, [&](const MarkerDetection& detection) {
        return options.marker_map->markers.count(detection.id) != 0;
      });
    }
    if (edit) edit(t, &detections);
    if (t >= blackout_begin && t < blackout_end) {
      frame.features = OrbFeatures();
      frame.ResetMatches();
      detections.clear();
    }
    run.reports.push_back(system.ProcessFrame(std::move(frame), detections));
  }
  system.Finish();
  run.trajectory = system.Trajectory();
  run.marker_map = system.MarkerMapOutput();
  run.stats = system.Stats();
  run.aligned = system.world_aligned();
  run.invariants = system.map().Read([](const MapData& data) { return data.CheckInvariants(); });
  return run;
}

// Scale of the Sim(3) that best maps the estimated positions onto the truth.
double AlignmentScale(const std::vector<StampedPose>& trajectory) {
  std::vector<Eigen::Vector3d> estimated, truth;
  for (const StampedPose& pose : trajectory) {
    estimated.push_back(pose.world_from_cam.translation);
    truth.push_back(SceneWorldFromCam(test_scene::SceneFrameOf(pose.timestamp_s)).translation);
  }
  const std::optional<Sim3> truth_from_estimate =
      UmeyamaAlignment(estimated, truth, AlignmentKind::kSimilarity);
  return truth_from_estimate ? truth_from_estimate->scale : 0.0;
}

// World-frame RMSE of the frames the keypoint map posed and of those the markers alone posed
// (before the map exists).
struct SplitRmse {
  double from_map_m = 0.0;
  double from_markers_m = 0.0;
  int num_from_map = 0;
};

SplitRmse RmseByPoseSource(const MarkerRun& run) {
  std::vector<StampedPose> from_map;
  std::vector<StampedPose> from_markers;
  EXPECT_EQ(run.reports.size(), run.trajectory.size());
  for (std::size_t i = 0; i < run.trajectory.size() && i < run.reports.size(); ++i) {
    (run.reports[i].marker_pose ? from_markers : from_map).push_back(run.trajectory[i]);
  }
  return {SceneAbsoluteRmse(from_map), SceneAbsoluteRmse(from_markers),
          static_cast<int>(from_map.size())};
}

TEST(SystemMarkers, OptionsCheck) {
  SystemOptions options;
  options.marker_map = SceneMarkers();
  EXPECT_TRUE(options.Check());
  options.world_anchoring.min_alignment_anchors = 1;
  EXPECT_FALSE(options.Check());
  options = {};
  options.marker_map = SceneMarkers();
  options.marker_fusion.max_marker_disagreement_m = -0.5;
  EXPECT_FALSE(options.Check());
}

TEST(SystemMarkers, BlockingRunIsInTheWorldFrameWithMetricScale) {
  const int num_frames = 80;
  const MarkerRun run = RunWithMarkers(true, num_frames);
  EXPECT_TRUE(run.aligned);
  // The map starts in the world from two marker locations, then is re-aligned once with
  // four anchors.
  EXPECT_EQ(run.stats.num_marker_initializations, 1);
  EXPECT_EQ(run.stats.world_anchoring.num_alignments, 2);
  EXPECT_EQ(run.invariants, "");
  // Every frame has a pose: the markers give one before the map is initialised.
  EXPECT_EQ(static_cast<int>(run.trajectory.size()), num_frames);
  EXPECT_TRUE(run.reports.front().marker_pose);
  EXPECT_GT(run.stats.num_marker_only_poses, 0);
  EXPECT_TRUE(run.reports.back().world_aligned);
  EXPECT_FALSE(run.reports.back().marker_pose);
  // Absolute error in the world frame, no alignment, of the frames the map tracked:
  // measured 5.4 mm (5.1 mm without the whole-map adjustment at the end). The first frames,
  // posed by the markers alone (LocateCamera) before the map exists: 19.8 mm.
  const SplitRmse rmse = RmseByPoseSource(run);
  EXPECT_GT(rmse.num_from_map, 60);
  EXPECT_LT(rmse.from_map_m, 0.0075);
  EXPECT_LT(rmse.from_markers_m, 0.03);
  EXPECT_EQ(run.stats.num_whole_map_marker_adjustments, 1);
  // Metric: the best similarity onto the truth has scale 1 within 1% (measured 0.2%).
  EXPECT_NEAR(AlignmentScale(run.trajectory), 1.0, 0.01);
}

TEST(SystemMarkers, ThreadedRunIsInTheWorldFrame) {
  const MarkerRun run = RunWithMarkers(false, 80);
  EXPECT_TRUE(run.aligned);
  EXPECT_EQ(run.invariants, "");
  EXPECT_EQ(run.trajectory.size(), 80u);
  // As the blocking run; the map's frames vary with thread timing: 3.3-7.0 mm over 60 runs
  // (median 3.6 mm); the markers-only frames 19.8 mm.
  const SplitRmse rmse = RmseByPoseSource(run);
  EXPECT_GT(rmse.num_from_map, 60);
  EXPECT_LT(rmse.from_map_m, 0.01);
  EXPECT_LT(rmse.from_markers_m, 0.03);
  EXPECT_NEAR(AlignmentScale(run.trajectory), 1.0, 0.01);
}

TEST(SystemMarkers, ThreadedRunMapsEachKeyframeBeforeTheNextFrameUntilAligned) {
  // synchronous_until_aligned: no marker before frame 60, so the map stays unaligned that
  // long and tracking waits for each of its keyframes' local mapping (the young-map rule is
  // off here): when ProcessFrame returns, every keyframe it inserted is mapped.
  const CameraModel camera = SceneCamera();
  SyntheticFeatureScene scene(camera);
  SystemOptions options;
  options.blocking = false;
  options.synchronous_young_map_keyframes = 0;
  options.synchronous_until_aligned = true;  // off by default
  options.marker_map = SceneMarkers();
  System system(camera, options);
  std::mt19937 rng(7);
  std::vector<int> truth;
  int checked = 0;
  bool aligned = false;
  for (int t = 0; t < 100; ++t) {
    const Rigid3 cam_from_world = SceneWorldFromCam(t).Inverse();
    Frame frame = scene.MakeFrame(FrameId(t), kSceneDt * t, cam_from_world, &truth);
    std::vector<MarkerDetection> detections;
    if (t >= 60) detections = SceneDetections(SceneMarkers(), camera, cam_from_world, rng);
    const FrameReport report = system.ProcessFrame(std::move(frame), detections);
    aligned = aligned || report.world_aligned;
    if (aligned || !report.new_keyframe || report.initialized_map) continue;
    const SystemStats stats = system.Stats();
    EXPECT_EQ(static_cast<int>(stats.local_mapping_ms.Count()),
              stats.num_keyframes_inserted - 2 * stats.num_initializations)
        << "frame " << t;
    ++checked;
  }
  EXPECT_GE(checked, 5);  // keyframes were inserted before the alignment
  EXPECT_TRUE(aligned);
  system.Finish();
}

TEST(SystemMarkers, FirstMarkerAfterBlackoutGivesAccuratePose) {
  // A 2 s blackout (40 frames) after the map is aligned.
  const MarkerRun run = RunWithMarkers(true, 110, 50, 90);
  EXPECT_GE(run.stats.num_losses, 1);
  // The blackout's frames are the ones left without a pose and without a marker in view.
  EXPECT_EQ(run.stats.num_unposed_without_markers, 40);
  const FrameReport& first = run.reports[90];
  ASSERT_TRUE(first.cam_from_world.has_value()) << first.message;
  const Eigen::Vector3d centre = first.cam_from_world->Inverse().translation;
  EXPECT_LT((centre - SceneWorldFromCam(90).translation).norm(), 0.05);
  // Tracking goes on in the world frame after the blackout.
  for (int t = 91; t < 110; ++t) EXPECT_TRUE(run.reports[t].cam_from_world.has_value()) << t;
  ASSERT_FALSE(run.trajectory.empty());
  EXPECT_LT(SceneAbsoluteRmse(run.trajectory), 0.02);
}

TEST(SystemMarkers, KnownMarkersAreOutputFixed) {
  const MarkerRun run = RunWithMarkers(true, 60);
  EXPECT_EQ(run.marker_map.markers.size(), SceneMarkers().markers.size());
  for (const auto& [id, info] : run.marker_map.markers) {
    EXPECT_TRUE(info.fixed) << id;
    EXPECT_EQ((info.world_from_marker.translation -
               SceneMarkers().markers.at(id).world_from_marker.translation).norm(), 0.0);
  }
}

// Issue-7 acceptance: mapped markers within 3 cm, and a false detection is not mapped.
TEST(SystemMarkers, MarkersTheMapLacksAreMappedOnline) {
  // Only marker 10 is known (marker 5, seen face-on, is too often ambiguous to locate the
  // camera alone); the ten others are mapped from the keyframes that see them. Frames 100
  // and 101 also detect a marker 33 that is not on the wall (a false detection).
  MarkerMap one = SceneMarkers();
  std::erase_if(one.markers, [](const auto& entry) { return entry.first != 10; });
  const DetectionEdit false_detection = [](int t, std::vector<MarkerDetection>* detections) {
    if (t != 100 && t != 101) return;
    MarkerDetection spurious;
    spurious.id = 33;
    spurious.corners = {Eigen::Vector2d(100, 100), Eigen::Vector2d(160, 102),
                        Eigen::Vector2d(158, 161), Eigen::Vector2d(99, 159)};
    detections->push_back(spurious);
  };
  const MarkerRun run = RunWithMarkers(true, 120, -1, -1, one, 3, false, false_detection);
  ASSERT_TRUE(run.aligned);
  EXPECT_EQ(run.invariants, "");
  const MarkerMap truth = SceneMarkers();
  EXPECT_EQ(run.marker_map.markers.count(33), 0u);
  ASSERT_TRUE(run.marker_map.markers.count(10));
  EXPECT_TRUE(run.marker_map.markers.at(10).fixed);
  int mapped = 0;
  for (const auto& [id, info] : run.marker_map.markers) {
    if (id == 10 || !truth.markers.count(id)) continue;
    EXPECT_FALSE(info.fixed) << id;
    EXPECT_DOUBLE_EQ(info.size, 0.4);
    const double error =
        (info.world_from_marker.translation - truth.markers.at(id).world_from_marker.translation)
            .norm();
    // Measured 1.4-5.8 mm (markers 1-9; marker 0 is seen by two keyframes only, too few to
    // be mapped). Before culled keyframes' marker views were kept for the final bundle
    // adjustment: 30-65 mm (the 7 keyframes left held too few views of the known marker).
    EXPECT_LT(error, 0.03) << "marker " << id;
    ++mapped;
  }
  // The camera's 3.6 m of travel sees the wall from x = -1.9 to 5.5 m: markers 0..10.
  EXPECT_GE(mapped, 8);
}

TEST(SystemMarkers, MappedMarkersLocateFramesWhereNoKnownMarkerIsSeen) {
  // Marker 10 alone is known; from frame 100 on it is hidden and only mapped markers are
  // in view. (The map is aligned at frame 91, measured.)
  MarkerMap one = SceneMarkers();
  std::erase_if(one.markers, [](const auto& entry) { return entry.first != 10; });
  const MarkerRun run = RunWithMarkers(true, 120, 100, 100, one, 3, true);
  const MarkerRun known_only = RunWithMarkers(true, 120, 100, 100, one, 0, true);
  int located = 0;
  for (int t = 100; t < 120; ++t) {
    EXPECT_EQ(known_only.reports[t].num_markers, 0) << t;
    if (run.reports[t].num_markers == 0) continue;
    ++located;
    ASSERT_TRUE(run.reports[t].cam_from_world.has_value()) << t;
    const Eigen::Vector3d centre = run.reports[t].cam_from_world->Inverse().translation;
    EXPECT_LT((centre - SceneWorldFromCam(t).translation).norm(), 0.05) << t;
  }
  EXPECT_GE(located, 15);
}

TEST(SystemMarkers, KeypointPoseThatTheMarkersContradictIsRejected) {
  // Frames 70-79: the markers are detected as a camera 1.5 m to the side would see them (a
  // keypoint pose in a look-alike place looks like this from the markers' side). The
  // keypoint pose is then rejected and the frames follow the markers; once the markers agree
  // again, tracking goes on near the truth.
  const CameraModel camera = SceneCamera();
  SyntheticFeatureScene scene(camera);
  SystemOptions options;
  options.marker_map = SceneMarkers();
  options.keyframes.min_frames_between = 0;
  System system(camera, options);
  std::mt19937 rng(7);
  std::vector<int> truth;
  const Rigid3 shift(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1.5, 0.0, 0.0));
  std::vector<FrameReport> reports;
  for (int t = 0; t < 110; ++t) {
    const Rigid3 cam_from_world = SceneWorldFromCam(t).Inverse();
    Frame frame = scene.MakeFrame(FrameId(t), kSceneDt * t, cam_from_world, &truth);
    const bool spoofed = t >= 70 && t < 80;
    const Rigid3 seen_from = spoofed ? (shift * SceneWorldFromCam(t)).Inverse() : cam_from_world;
    reports.push_back(system.ProcessFrame(std::move(frame), SceneDetections(SceneMarkers(), camera, seen_from, rng)));
  }
  system.Finish();
  ASSERT_TRUE(system.world_aligned());
  EXPECT_GE(system.Stats().marker_fusion.num_rejected_poses, 1);
  for (int t = 70; t < 80; ++t) {
    if (!reports[t].cam_from_world) continue;
    const Eigen::Vector3d centre = reports[t].cam_from_world->Inverse().translation;
    // Never the keypoint pose (at the truth): either no pose or the markers' one.
    EXPECT_GT((centre - SceneWorldFromCam(t).translation).norm(), 1.0) << t;
  }
  int near_truth = 0;
  for (int t = 100; t < 110; ++t) {
    if (!reports[t].cam_from_world) continue;
    const Eigen::Vector3d centre = reports[t].cam_from_world->Inverse().translation;
    if ((centre - SceneWorldFromCam(t).translation).norm() < 0.05) ++near_truth;
  }
  EXPECT_GE(near_truth, 8);
}

// Frame t sees the markers as from a camera shift_at(t) metres along x of the truth (none
// when nullopt): to the System, its map drifted that far. The keypoints, a rigid scene, keep
// saying otherwise, so a correction can only meet the markers part way.
using MarkerShift = std::function<std::optional<double>(int t)>;
struct DriftRun {
  std::vector<FrameReport> reports;
  SystemStats stats;
};

DriftRun RunWithShiftedMarkers(const MarkerShift& shift_at,
                               const std::function<void(SystemOptions*)>& configure = {}) {
  const CameraModel camera = SceneCamera();
  SyntheticFeatureScene scene(camera);
  SystemOptions options;
  options.marker_map = SceneMarkers();
  options.keyframes.min_frames_between = 0;
  if (configure) configure(&options);
  System system(camera, options);
  std::mt19937 rng(7);
  std::vector<int> truth;
  DriftRun run;
  for (int t = 0; t < 140; ++t) {
    const Rigid3 cam_from_world = SceneWorldFromCam(t).Inverse();
    Frame frame = scene.MakeFrame(FrameId(t), kSceneDt * t, cam_from_world, &truth);
    std::vector<MarkerDetection> detections;
    if (const std::optional<double> shift = shift_at(t)) {
      const Rigid3 seen_from(Eigen::Quaterniond::Identity(), Eigen::Vector3d(*shift, 0.0, 0.0));
      detections = SceneDetections(SceneMarkers(), camera,
                                   (seen_from * SceneWorldFromCam(t)).Inverse(), rng);
    }
    run.reports.push_back(system.ProcessFrame(std::move(frame), detections));
  }
  system.Finish();
  run.stats = system.Stats();
  return run;
}

// Markers where they are in frames 0-39, none in 40-99, then seen 0.6 m off.
std::optional<double> ShiftAfterGap(int t) {
  if (t < 40) return 0.0;
  if (t < 100) return std::nullopt;
  return 0.6;
}

// Distance from frame t's reported camera centre to where its markers put it.
double DistanceFromMarkers(const DriftRun& run, const MarkerShift& shift_at, int t) {
  const Eigen::Vector3d centre = run.reports[t].cam_from_world->Inverse().translation;
  return (centre - SceneWorldFromCam(t).translation - Eigen::Vector3d(*shift_at(t), 0.0, 0.0))
      .norm();
}

// The map seen 0.6 m off by the markers after a gap: the first keypoint pose beyond the
// 0.5 m gate (frame 100) is rejected, the frame is relocalised from its markers and becomes a
// keyframe whose marker location corrects the map. From then on the keypoints track the
// camera within the gate of the markers (no further rejection), and no new map is started.
void ExpectMarkersTakeOverAfterAGap(const DriftRun& run) {
  EXPECT_EQ(run.stats.marker_fusion.num_rejected_poses, 1);
  EXPECT_GE(run.stats.world_anchoring.num_drift_corrections, 1);
  EXPECT_EQ(run.stats.map_session.num_resets, 0);
  ASSERT_TRUE(run.reports[100].cam_from_world);
  EXPECT_TRUE(run.reports[100].new_keyframe);
  for (int t = 101; t < 140; ++t) {
    ASSERT_TRUE(run.reports[t].cam_from_world) << t;
    EXPECT_FALSE(run.reports[t].marker_pose) << t;
    EXPECT_LT(DistanceFromMarkers(run, ShiftAfterGap, t), 0.5) << t;
  }
}

TEST(SystemMarkers, MarkersThatDisagreeAfterAGapRelocaliseAndCorrectTheMap) {
  const DriftRun run = RunWithShiftedMarkers(ShiftAfterGap);
  ExpectMarkersTakeOverAfterAGap(run);
  EXPECT_LT(DistanceFromMarkers(run, ShiftAfterGap, 100), 0.15);  // the relocalised pose
}

TEST(SystemMarkers, ThreadedDriftCorrectionSeesTheKeyframesMarkers) {
  // Threaded, each keyframe mapped before the next frame: the mapping thread corrects the
  // map only if the keyframe's marker location was stored before the keyframe was queued.
  // Frame 100 itself is not checked: here the map is re-aligned to the world in that frame,
  // from four anchors of which the new one is 0.6 m off, and the frame moves with it.
  ExpectMarkersTakeOverAfterAGap(RunWithShiftedMarkers(ShiftAfterGap, [](SystemOptions* options) {
    options->blocking = false;
    options->synchronous_young_map_keyframes = 1000;
  }));
}

}  // namespace
}  // namespace arucoslam
