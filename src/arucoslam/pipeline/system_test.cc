#include "arucoslam/pipeline/system.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "arucoslam/geometry/umeyama.h"
#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/slam/synthetic_features.h"

namespace arucoslam {
namespace {

CameraModel TestCamera() {
  return PinholeCamera(640, 480, 500.0);
}

// A sideways, slightly weaving and turning camera path (20 Hz); `moving` false holds it still.
Rigid3 WorldFromCam(int t, bool moving = true) {
  if (!moving) t = 0;
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.003 * t, Eigen::Vector3d::UnitY())),
                Eigen::Vector3d(0.03 * t, 0.2 * std::sin(t / 15.0), 0.003 * t));
}

struct RunResult {
  std::vector<StampedPose> trajectory;
  int first_initialised = -1;
  SystemStats stats;
  std::size_t num_keyframes = 0;
  std::string invariants;
};

std::shared_ptr<const Vocabulary> ShippedVocabulary() {
  static const auto vocabulary = std::make_shared<const Vocabulary>(Vocabulary::Load(
      std::filesystem::path(ARUCOSLAM_SOURCE_DIR) / "data" / "vocabulary" / "orb_k10_l5.bin"));
  return vocabulary;
}

RunResult RunSynthetic(bool blocking, int num_frames, bool moving = true,
                       std::shared_ptr<const Vocabulary> vocabulary = nullptr,
                       int max_backfill_frames = SystemOptions().map_session.max_backfill_frames,
                       bool live_source = false) {
  SyntheticFeatureScene scene(TestCamera());
  SystemOptions options;
  options.blocking = blocking;
  options.live_source = live_source;
  options.map_session.max_backfill_frames = max_backfill_frames;
  options.vocabulary = std::move(vocabulary);
  System system(TestCamera(), options);
  RunResult run;
  std::vector<int> truth;
  for (int t = 0; t < num_frames; ++t) {
    const FrameReport report = system.ProcessFrame(
        scene.MakeFrame(FrameId(t), 0.05 * t, WorldFromCam(t, moving).Inverse(), &truth));
    if (report.initialized_map && run.first_initialised < 0) run.first_initialised = t;
  }
  system.Finish();
  run.trajectory = system.Trajectory();
  run.stats = system.Stats();
  run.num_keyframes = system.map().NumKeyframes();
  run.invariants = system.map().Read([](const MapData& data) { return data.CheckInvariants(); });
  return run;
}

// RMS position error after Sim(3) alignment, over the frames of the trajectory.
double AlignedRmsError(const std::vector<StampedPose>& trajectory) {
  std::vector<Eigen::Vector3d> estimated, truth;
  for (const StampedPose& pose : trajectory) {
    estimated.push_back(pose.world_from_cam.translation);
    truth.push_back(WorldFromCam(static_cast<int>(std::lround(pose.timestamp_s / 0.05))).translation);
  }
  const std::optional<Sim3> truth_from_estimate =
      UmeyamaAlignment(estimated, truth, AlignmentKind::kSimilarity);
  if (!truth_from_estimate) return 1e9;
  double sum = 0.0;
  for (std::size_t i = 0; i < estimated.size(); ++i) {
    sum += ((*truth_from_estimate) * estimated[i] - truth[i]).squaredNorm();
  }
  return std::sqrt(sum / estimated.size());
}

TEST(System, OptionsCheck) {
  EXPECT_TRUE(SystemOptions().Check());
  SystemOptions options;
  options.mapper_queue_capacity = 0;
  EXPECT_FALSE(options.Check());
  EXPECT_THROW(System(TestCamera(), options), std::invalid_argument);
}

TEST(System, OptionsCheckSaysWhichValueIsWrong) {
  SystemOptions options;
  options.mapper.bundle_adjustment.solver.max_iterations = 0;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "mapper.bundle_adjustment.solver.max_iterations must be >= 1, is 0");
  options = {};
  options.refine_min_inlier_fraction = 1.5;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "refine_min_inlier_fraction must be in (0, 1], is 1.5");
  options = {};
  options.min_locating_marker_keyframes = -1;  // the flow's marker_mapping.min_locating_keyframes
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "min_locating_marker_keyframes must be >= 0, is -1");
  options = {};
  options.refine_min_inlier_fraction = 1.5;
  try {
    System system(TestCamera(), options);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(),
                 "System: invalid SystemOptions: refine_min_inlier_fraction must be in (0, 1], is "
                 "1.5");
  }
}

TEST(System, BlockingRunTracksSyntheticSequenceAccurately) {
  const int num_frames = 80;
  const RunResult run = RunSynthetic(true, num_frames);
  ASSERT_GE(run.first_initialised, 1);
  EXPECT_LE(run.first_initialised, 10);  // half a second
  const int after_init = num_frames - run.first_initialised;
  // Both initial frames plus every tracked frame after them have a pose.
  EXPECT_GE(static_cast<int>(run.trajectory.size()), 0.95 * after_init);
  EXPECT_EQ(run.stats.num_frames, num_frames);
  EXPECT_EQ(run.stats.num_losses, 0);
  EXPECT_EQ(run.stats.num_initializations, 1);
  EXPECT_GE(run.num_keyframes, 3u);
  EXPECT_GE(run.stats.local_mapping_ms.Count(), 1u);
  EXPECT_EQ(run.invariants, "");
  // The camera travels about 2.4 m; the error bound is 1% of that.
  EXPECT_LT(AlignedRmsError(run.trajectory), 0.024);
}

TEST(System, FramePosesAreRefinedAgainstTheFinalMap) {
  // Noisier keypoints: a frame's offset from its keyframe, fixed when it was tracked, is
  // worse than what the final map gives it.
  const auto run = [](bool refine) {
    SyntheticFeatureOptions scene_options;
    scene_options.pixel_noise = 1.0;
    SyntheticFeatureScene scene(TestCamera(), scene_options);
    SystemOptions options;
    options.refine_frame_poses = refine;
    System system(TestCamera(), options);
    std::vector<int> truth;
    for (int t = 0; t < 150; ++t) {
      system.ProcessFrame(scene.MakeFrame(FrameId(t), 0.05 * t, WorldFromCam(t).Inverse(), &truth));
    }
    system.Finish();
    return std::make_pair(system.Trajectory(), system.Stats());
  };
  const auto [kept, kept_stats] = run(false);
  const auto [refined, refined_stats] = run(true);
  ASSERT_EQ(kept.size(), refined.size());
  EXPECT_EQ(kept_stats.num_refined_frame_poses, 0);
  EXPECT_GE(refined_stats.num_refined_frame_poses, 0.9 * refined.size());
  const double kept_error = AlignedRmsError(kept);
  const double refined_error = AlignedRmsError(refined);
  std::printf("aligned RMS error: keyframe offsets %.5f m, refined %.5f m\n", kept_error,
              refined_error);
  EXPECT_LT(refined_error, kept_error);
}

TEST(System, FramesBeforeTheInitialisationAreTrackedBackwards) {
  // The frames between the initialisation reference (frame 0) and the frame that completed
  // the map get poses in the same map, as accurate as the rest.
  const int num_frames = 40;
  const RunResult without = RunSynthetic(true, num_frames, true, nullptr, 0);
  const RunResult run = RunSynthetic(true, num_frames);
  ASSERT_GE(run.first_initialised, 3);
  ASSERT_EQ(without.first_initialised, run.first_initialised);
  const auto has_pose = [](const RunResult& result, int t) {
    return std::any_of(result.trajectory.begin(), result.trajectory.end(), [&](const StampedPose& pose) {
      return std::lround(pose.timestamp_s / 0.05) == t;
    });
  };
  for (int t = 0; t <= run.first_initialised; ++t) {
    EXPECT_TRUE(has_pose(run, t)) << t;
    // Without the backfill only the two initial frames have a pose.
    EXPECT_EQ(has_pose(without, t), t == 0 || t == run.first_initialised) << t;
  }
  // Every pose is counted as tracked but the reference frame's (its report had none).
  EXPECT_EQ(run.stats.num_tracked + 1, static_cast<int>(run.trajectory.size()));
  for (std::size_t i = 1; i < run.trajectory.size(); ++i) {
    EXPECT_LT(run.trajectory[i - 1].timestamp_s, run.trajectory[i].timestamp_s);
  }
  // The camera travels about 1.2 m; the error bound is 1% of that.
  EXPECT_LT(AlignedRmsError(run.trajectory), 0.012);
}

TEST(System, BackfillGoesBackThroughReplacedInitialisationReferences) {
  // The camera first turns in place (pure rotation: no initialisation) far enough that the
  // initialisation reference is replaced twice, then moves sideways. Every frame of the turn
  // gets a pose back from the map once it exists.
  const int turn_frames = 40;
  const double turn_rad_per_frame = 0.8 * M_PI / 180.0;
  const auto world_from_cam = [&](int t) {
    const int turned = std::min(t, turn_frames);
    const int moved = std::max(0, t - turn_frames);
    return Rigid3(Eigen::Quaterniond(
                      Eigen::AngleAxisd(turn_rad_per_frame * turned, Eigen::Vector3d::UnitY())),
                  Eigen::Vector3d(0.03 * moved, 0.0, 0.0));
  };
  SyntheticFeatureScene scene(TestCamera());
  System system(TestCamera(), SystemOptions());
  std::vector<int> truth;
  const int num_frames = turn_frames + 30;
  int replaced = 0;
  for (int t = 0; t < num_frames; ++t) {
    const FrameReport report = system.ProcessFrame(
        scene.MakeFrame(FrameId(t), 0.05 * t, world_from_cam(t).Inverse(), &truth));
    if (t > 0 && report.message.find("100 needed") != std::string::npos) ++replaced;
    if (t < turn_frames) EXPECT_FALSE(report.cam_from_world.has_value()) << t;
  }
  system.Finish();
  EXPECT_GE(replaced, 2);
  const std::vector<StampedPose> trajectory = system.Trajectory();
  ASSERT_EQ(static_cast<int>(trajectory.size()), num_frames);
  // Orientation from the map (up to its frame) against the truth: the turn is recovered.
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    EXPECT_EQ(std::lround(trajectory[i].timestamp_s / 0.05), static_cast<long>(i));
    const Rigid3 first_from_cam =
        trajectory.front().world_from_cam.Inverse() * trajectory[i].world_from_cam;
    const Rigid3 true_first_from_cam =
        world_from_cam(0).Inverse() * world_from_cam(static_cast<int>(i));
    EXPECT_LT(first_from_cam.rotation.angularDistance(true_first_from_cam.rotation), 0.01) << i;
  }
}

TEST(System, BlockingRunIsDeterministic) {
  const RunResult a = RunSynthetic(true, 40);
  const RunResult b = RunSynthetic(true, 40);
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
  ASSERT_GT(a.trajectory.size(), 20u);
  for (std::size_t i = 0; i < a.trajectory.size(); ++i) {
    EXPECT_EQ(a.trajectory[i].timestamp_s, b.trajectory[i].timestamp_s);
    EXPECT_EQ(a.trajectory[i].world_from_cam.translation, b.trajectory[i].world_from_cam.translation);
  }
}

TEST(System, ThreadedRunTracksSyntheticSequence) {
  const int num_frames = 80;
  const RunResult run = RunSynthetic(false, num_frames);
  ASSERT_GE(run.first_initialised, 1);
  EXPECT_GE(static_cast<int>(run.trajectory.size()), 0.95 * (num_frames - run.first_initialised));
  EXPECT_EQ(run.invariants, "");
  EXPECT_LT(AlignedRmsError(run.trajectory), 0.024);
}

TEST(System, ThreadedRunOfALiveSourceTracksSyntheticSequence) {
  // A live source's young map takes keyframes only from an idle mapper; tracking never waits.
  const int num_frames = 80;
  const RunResult run = RunSynthetic(false, num_frames, true, nullptr,
                                     SystemOptions().map_session.max_backfill_frames, true);
  ASSERT_GE(run.first_initialised, 1);
  EXPECT_GE(static_cast<int>(run.trajectory.size()), 0.95 * (num_frames - run.first_initialised));
  EXPECT_GE(run.stats.num_keyframes_inserted, 4);
  EXPECT_EQ(run.invariants, "");
  EXPECT_LT(AlignedRmsError(run.trajectory), 0.024);
}

TEST(System, ThreadedRunMapsAYoungMapsKeyframesBeforeTheNextFrame) {
  // While the map holds at most synchronous_young_map_keyframes keyframes, tracking waits
  // for each new keyframe's local mapping: when ProcessFrame returns, every keyframe it
  // inserted is mapped (the two of the initial map are not mapped by local mapping).
  SyntheticFeatureScene scene(TestCamera());
  SystemOptions options;
  options.blocking = false;
  options.synchronous_young_map_keyframes = 1000;
  System system(TestCamera(), options);
  std::vector<int> truth;
  int checked = 0;
  for (int t = 0; t < 80; ++t) {
    const FrameReport report = system.ProcessFrame(
        scene.MakeFrame(FrameId(t), 0.05 * t, WorldFromCam(t).Inverse(), &truth));
    const SystemStats stats = system.Stats();
    if (!report.new_keyframe || report.initialized_map) continue;
    EXPECT_EQ(static_cast<int>(stats.local_mapping_ms.Count()),
              stats.num_keyframes_inserted - 2 * stats.num_initializations)
        << "frame " << t;
    ++checked;
  }
  EXPECT_GE(checked, 5);  // keyframes were inserted after the initial map
  system.Finish();
  EXPECT_LT(AlignedRmsError(system.Trajectory()), 0.024);
}

TEST(System, PlaceRecognitionAlongsideThreadedMappingKeepsTheRunIntact) {
  // Keyframes go through the database and loop detection on their own thread; the route
  // never comes back, so nothing may be closed and the result matches the plain run.
  const int num_frames = 80;
  const RunResult run = RunSynthetic(false, num_frames, true, ShippedVocabulary());
  ASSERT_GE(run.first_initialised, 1);
  EXPECT_GE(static_cast<int>(run.trajectory.size()), 0.95 * (num_frames - run.first_initialised));
  EXPECT_EQ(run.invariants, "");
  EXPECT_LT(AlignedRmsError(run.trajectory), 0.024);
  EXPECT_GE(run.stats.places.loop_detection_ms.Count(), 1u);  // the loop thread ran
  EXPECT_TRUE(run.stats.places.loops.empty());
  EXPECT_EQ(run.stats.places.num_relocalizations, 0);
}

TEST(System, KidnappedCameraIsRelocalisedFromThePlaceDatabase) {
  // The camera travels 80 frames, then is carried back to where it was at frame 10 and goes
  // on from there. The reference-keyframe fallback is switched off (in this scene it would
  // find the kidnapped camera by itself): every frame the motion model cannot track is lost
  // and only the place database can give its pose back, in the same map frame and scale.
  SyntheticFeatureScene scene(TestCamera());
  SystemOptions options;
  options.vocabulary = ShippedVocabulary();
  options.tracker.min_reference_matches = 1000000;
  System system(TestCamera(), options);
  std::vector<int> truth;
  int frame_index = 0;
  auto feed = [&](int t) {
    const FrameReport report = system.ProcessFrame(
        scene.MakeFrame(FrameId(frame_index), 0.05 * frame_index, WorldFromCam(t).Inverse(), &truth));
    ++frame_index;
    return report;
  };
  for (int t = 0; t < 80; ++t) feed(t);
  const int relocalisations_before = system.Stats().places.num_relocalizations;
  int first_relocalised = -1;
  int posed_after = 0;
  for (int t = 10; t < 30; ++t) {
    const FrameReport report = feed(t);
    if (report.cam_from_world && first_relocalised < 0) first_relocalised = t;
    if (report.cam_from_world) ++posed_after;
  }
  system.Finish();
  const SystemStats stats = system.Stats();
  EXPECT_EQ(first_relocalised, 10);  // the first frame after the kidnapping
  EXPECT_EQ(posed_after, 20);
  EXPECT_GT(stats.places.num_relocalizations, relocalisations_before);
  EXPECT_EQ(stats.map_session.num_resets, 0);
  // Every pose, before and after, against the truth after one Sim(3) alignment: the
  // relocalised leg is in the same map frame and scale as the first one.
  std::vector<Eigen::Vector3d> estimated, expected;
  int after_kidnap = 0;
  for (const StampedPose& pose : system.Trajectory()) {
    const int index = static_cast<int>(std::lround(pose.timestamp_s / 0.05));
    estimated.push_back(pose.world_from_cam.translation);
    expected.push_back(WorldFromCam(index < 80 ? index : index - 70).translation);
    if (index >= 80) ++after_kidnap;
  }
  EXPECT_EQ(after_kidnap, 20);
  const std::optional<Sim3> aligned =
      UmeyamaAlignment(estimated, expected, AlignmentKind::kSimilarity);
  ASSERT_TRUE(aligned.has_value());
  double worst = 0.0;
  for (std::size_t i = 0; i < estimated.size(); ++i) {
    worst = std::max(worst, ((*aligned) * estimated[i] - expected[i]).norm());
  }
  EXPECT_LT(worst, 0.05);  // the route is 2.4 m long
  EXPECT_EQ(system.map().Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

TEST(System, StaticSyntheticCameraNeverInitialises) {
  const RunResult run = RunSynthetic(true, 30, /*moving=*/false);
  EXPECT_EQ(run.first_initialised, -1);
  EXPECT_GT(run.stats.num_initialization_attempts, 20);
  EXPECT_EQ(run.stats.num_initializations, 0);
  EXPECT_TRUE(run.trajectory.empty());
  EXPECT_EQ(run.num_keyframes, 0u);
}

TEST(System, RealEurocStaticCameraNeverInitialises) {
  const std::filesystem::path root =
      std::filesystem::path(ARUCOSLAM_TEST_DATA_DIR) / "euroc_v101_micro";
  if (!std::filesystem::exists(root)) GTEST_SKIP() << "test data missing: " << root;
  const Dataset dataset = Dataset::Open(root);
  System system(dataset.camera());
  for (std::size_t i = 0; i < dataset.size(); ++i) {
    const FrameReport report = system.ProcessImage(dataset.LoadImage(i), dataset.frame(i).timestamp_s);
    EXPECT_FALSE(report.cam_from_world.has_value()) << "frame " << i << ": " << report.message;
  }
  system.Finish();
  const SystemStats stats = system.Stats();
  EXPECT_EQ(stats.num_frames, static_cast<int>(dataset.size()));
  EXPECT_GT(stats.num_initialization_attempts, 50);  // it kept trying
  EXPECT_EQ(stats.num_initializations, 0);
  EXPECT_EQ(system.map().NumKeyframes(), 0u);
  EXPECT_TRUE(system.Trajectory().empty());
  EXPECT_EQ(stats.extraction_ms.Count(), dataset.size());
}

}  // namespace
}  // namespace arucoslam
