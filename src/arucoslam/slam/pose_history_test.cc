// PoseHistory on hand-made maps: a recorded pose follows its keyframe (moved, culled, scaled
// by a loop, merged from a closed map, aligned to the world), is frozen at a map reset, gives
// way to a backfilled pose, and is refined against the points it matched.
#include "arucoslam/slam/pose_history.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace arucoslam {
namespace {

Rigid3 Pose(double yaw, const Eigen::Vector3d& translation) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())), translation);
}

KeyframeId AddKeyframe(Map* map, double timestamp_s, const Rigid3& cam_from_world) {
  Keyframe keyframe;
  keyframe.timestamp_s = timestamp_s;
  keyframe.cam_from_world = cam_from_world;
  return map->Write([&](MapData& data) { return data.AddKeyframe(keyframe); });
}

void MoveKeyframe(Map* map, KeyframeId id, const Rigid3& cam_from_world) {
  map->Write([&](MapData& data) { data.SetKeyframePose(id, cam_from_world); });
}

Frame FrameAt(double timestamp_s, const Rigid3& cam_from_world) {
  Frame frame;
  frame.timestamp_s = timestamp_s;
  frame.cam_from_world = cam_from_world;
  return frame;
}

void ExpectSamePose(const Rigid3& expected, const Rigid3& actual, double tolerance = 1e-12) {
  EXPECT_NEAR((expected.translation - actual.translation).norm(), 0.0, tolerance);
  EXPECT_NEAR(expected.rotation.angularDistance(actual.rotation), 0.0, tolerance);
}

const Rigid3 kKeyframe = Pose(0.3, {1.0, -0.5, 2.0});
const Rigid3 kFrame = Pose(0.4, {1.2, -0.4, 2.1});
const Rigid3 kKeyframeMoved = Pose(-0.2, {0.5, 0.7, 1.0});
// kFrame recorded against kKeyframe once the keyframe is at kKeyframeMoved:
// cam_from_world_now = cam_from_keyframe * keyframe_from_world_now.
const Rigid3 kFrameMoved = kFrame * kKeyframe.Inverse() * kKeyframeMoved;

TEST(PoseHistory, PoseFollowsItsKeyframeByTheKeyframesMotion) {
  Map map;
  const KeyframeId keyframe = AddKeyframe(&map, 0.0, kKeyframe);
  PoseHistory history(false, {});
  history.Record(map, FrameAt(0.1, kFrame), keyframe, true, std::nullopt);
  MoveKeyframe(&map, keyframe, kKeyframeMoved);
  const std::vector<StampedPose> poses = history.CurrentMapPoses(map, true);
  ASSERT_EQ(poses.size(), 1u);
  ExpectSamePose(kFrameMoved.Inverse(), poses[0].world_from_cam);
}

TEST(PoseHistory, OffsetFromTheKeyframeGrowsWithTheScaleOfALoopAroundIt) {
  Map map;
  const KeyframeId keyframe = AddKeyframe(&map, 0.0, kKeyframe);
  double scale = 1.5;  // the keyframe's scale when the pose is recorded
  PoseHistory history(false, [&](KeyframeId) { return scale; });
  history.Record(map, FrameAt(0.1, kFrame), keyframe, true, std::nullopt);
  scale = 3.0;  // a loop doubled the map around the keyframe
  Rigid3 cam_from_keyframe = kFrame * kKeyframe.Inverse();
  cam_from_keyframe.translation *= 2.0;
  const std::vector<StampedPose> poses = history.CurrentMapPoses(map, true);
  ExpectSamePose((cam_from_keyframe * kKeyframe).Inverse(), poses.at(0).world_from_cam);
}

TEST(PoseHistory, PoseOfACulledKeyframeFollowsTheKeyframeNearestInTime) {
  Map map;
  const KeyframeId first = AddKeyframe(&map, 0.0, Pose(0.0, {0.0, 0.0, 0.0}));
  const KeyframeId culled = AddKeyframe(&map, 1.0, kKeyframe);
  const KeyframeId later = AddKeyframe(&map, 2.0, Pose(0.1, {0.3, 0.0, 0.2}));
  PoseHistory history(false, {});
  history.Record(map, FrameAt(1.2, kFrame), culled, true, std::nullopt);
  history.RememberKeyframePoses(map);
  ASSERT_TRUE(map.Write([&](MapData& data) { return data.EraseKeyframe(culled); }));
  history.ReanchorOrphans(map);
  EXPECT_EQ(history.poses().at(0).reference, later);  // 0.8 s away, `first` 1.2 s
  EXPECT_NE(history.poses().at(0).reference, first);
  MoveKeyframe(&map, later, kKeyframeMoved);
  const Rigid3 cam_from_later = kFrame * Pose(0.1, {0.3, 0.0, 0.2}).Inverse();
  ExpectSamePose((cam_from_later * kKeyframeMoved).Inverse(),
                 history.CurrentMapPoses(map, true).at(0).world_from_cam);
}

TEST(PoseHistory, LastPoseCorrectionCarriesTheRecordedPoseToWhereItsKeyframeIsNow) {
  Map map;
  const KeyframeId keyframe = AddKeyframe(&map, 0.0, kKeyframe);
  PoseHistory history(false, {});
  EXPECT_FALSE(history.LastPoseCorrection(map).has_value());  // nothing recorded
  history.Record(map, FrameAt(0.1, kFrame), keyframe, true, std::nullopt);
  MoveKeyframe(&map, keyframe, kKeyframeMoved);
  const std::optional<Sim3> correction = history.LastPoseCorrection(map);
  ASSERT_TRUE(correction.has_value());
  EXPECT_NEAR(correction->scale, 1.0, 1e-12);
  ExpectSamePose(kFrameMoved, correction->TransformPose(kFrame.Inverse()).Inverse());
}

TEST(PoseHistory, AlignmentMovesPosesOutsideTheWorldWithTheMapAndLeavesMarkerPoses) {
  Map map;
  const KeyframeId keyframe = AddKeyframe(&map, 0.0, kKeyframe);
  PoseHistory history(false, {});
  Frame seen_by_markers = FrameAt(0.05, Pose(1.0, {4.0, 0.0, 1.0}));
  history.RecordMarkerPose(seen_by_markers, *seen_by_markers.cam_from_world);
  history.Record(map, FrameAt(0.1, kFrame), keyframe, false, std::nullopt);
  const Sim3 world_from_map(2.5,
                            Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitX())),
                            Eigen::Vector3d(3.0, -1.0, 0.5));
  const auto to_world = [&](const Rigid3& cam_from_map) {
    return world_from_map.TransformPose(cam_from_map.Inverse());
  };
  MoveKeyframe(&map, keyframe, to_world(kKeyframe).Inverse());
  history.MoveIntoWorld(world_from_map, false, {});
  const std::vector<StampedPose> poses = history.CurrentMapPoses(map, true);
  ASSERT_EQ(poses.size(), 2u);
  ExpectSamePose(seen_by_markers.cam_from_world->Inverse(), poses[0].world_from_cam);
  ExpectSamePose(to_world(kFrame), poses[1].world_from_cam, 1e-9);
}

TEST(PoseHistory, ResetFreezesWorldPosesAtTheirMarkerLocationOrKeyframeAndDropsTheRest) {
  Map map;
  const KeyframeId keyframe = AddKeyframe(&map, 0.0, kKeyframe);
  MarkerFix fix;
  fix.world_from_cam = Pose(0.9, {5.0, 1.0, 1.5});
  PoseHistory history(false, {});
  history.Record(map, FrameAt(0.1, kFrame), keyframe, true, std::nullopt);
  history.Record(map, FrameAt(0.2, kFrame), keyframe, false, fix);
  history.Record(map, FrameAt(0.3, kFrame), keyframe, false, std::nullopt);  // not in the world
  MoveKeyframe(&map, keyframe, kKeyframeMoved);
  history.FreezeForReset(map, /*kept_for_merge=*/false);
  ASSERT_EQ(history.poses().size(), 2u);
  EXPECT_FALSE(history.poses()[0].reference.IsValid());
  EXPECT_FALSE(history.poses()[0].closed_reference.IsValid());
  ExpectSamePose(kFrameMoved, history.poses()[0].cam_from_world);
  EXPECT_TRUE(history.poses()[1].in_world);
  ExpectSamePose(fix.world_from_cam.Inverse(), history.poses()[1].cam_from_world);
  // Frozen: the keyframe moving again no longer moves them.
  MoveKeyframe(&map, keyframe, kKeyframe);
  ExpectSamePose(kFrameMoved.Inverse(), history.CurrentMapPoses(map, true).at(0).world_from_cam);
}

TEST(PoseHistory, PosesOfAMergedClosedMapFollowTheirKeyframesUnderTheNewIds) {
  Map closed;
  const KeyframeId old_id = AddKeyframe(&closed, 0.0, kKeyframe);
  PoseHistory history(false, {});
  history.Record(closed, FrameAt(0.1, kFrame), old_id, true, std::nullopt);
  history.FreezeForReset(closed, /*kept_for_merge=*/true);
  EXPECT_EQ(history.poses().at(0).closed_reference, old_id);
  Map current;
  AddKeyframe(&current, 5.0, Pose(0.0, {9.0, 9.0, 9.0}));
  const KeyframeId new_id = AddKeyframe(&current, 0.0, kKeyframe);
  AbsorbedIds ids;
  ids.keyframes[old_id] = new_id;
  EXPECT_EQ(history.FollowMergedMap(current, ids), 1);
  EXPECT_EQ(history.poses().at(0).reference, new_id);
  MoveKeyframe(&current, new_id, kKeyframeMoved);
  ExpectSamePose(kFrameMoved.Inverse(),
                 history.CurrentMapPoses(current, true).at(0).world_from_cam);
}

TEST(PoseHistory, BackfilledFramesReplaceMarkerOnlyPosesOfTheSameFramesInTimeOrder) {
  Map map;
  const KeyframeId keyframe = AddKeyframe(&map, 0.0, kKeyframe);
  PoseHistory history(false, {});
  history.RecordMarkerPose(FrameAt(0.5, kFrame), kFrame);
  history.RecordMarkerPose(FrameAt(1.5, kFrame), kFrame);
  history.Record(map, FrameAt(2.0, kFrame), keyframe, true, std::nullopt);
  const std::vector<Frame> tracked = {FrameAt(1.0, kFrame), FrameAt(0.5, kFrame)};
  EXPECT_EQ(history.MergeBackfill(map, tracked, keyframe, true, std::nullopt), 1);
  std::vector<double> times;
  for (const TrackedPose& pose : history.poses()) times.push_back(pose.timestamp_s);
  EXPECT_EQ(times, (std::vector<double>{0.5, 1.0, 1.5, 2.0}));
  EXPECT_EQ(history.poses()[0].reference, keyframe);     // the keypoint pose
  EXPECT_FALSE(history.poses()[2].reference.IsValid());  // still marker-only
}

TEST(PoseHistory, FramesWithoutPoseCountUnlessTheTrajectoryPosedThemLater) {
  PoseHistory history(false, {});
  for (double t : {0.1, 0.2, 0.3}) history.NoteUnposedWithoutMarkers(t);
  EXPECT_EQ(history.CountUnposedWithoutMarkers({{0.2, Rigid3()}, {0.4, Rigid3()}}), 2);
}

const Rigid3 kTruth = Pose(0.05, {0.1, 0.0, 0.2});
const Rigid3 kRecorded = Pose(0.07, {0.15, 0.03, 0.2});

// A frame that sees 30 points ahead of a keyframe at the origin from kTruth but was recorded
// at kRecorded, with its matches kept for the refinement.
class PoseHistoryRefinement : public ::testing::Test {
 protected:
  PoseHistoryRefinement() {
    Frame frame = FrameAt(0.1, kRecorded);
    frame.camera.fx = frame.camera.fy = 500.0;
    frame.camera.cx = 320.0;
    frame.camera.cy = 240.0;
    intrinsics_ = PinholeIntrinsics::FromCamera(frame.camera);
    for (int i = 0; i < 30; ++i) {
      MapPoint point;
      point.p_in_world =
          Eigen::Vector3d(-1.0 + 0.07 * i, 0.5 * std::sin(1.3 * i), 4.0 + 0.1 * (i % 7));
      points_.push_back(map_.Write([&](MapData& data) { return data.AddMapPoint(point); }));
      const Eigen::Vector3d p_in_cam = kTruth * point.p_in_world;
      frame.features.keypoints.emplace_back(0.0f, 0.0f, 31.0f);
      frame.features.undistorted.push_back(p_in_cam.head<2>() / p_in_cam.z());
      frame.map_point_ids.push_back(points_.back());
      frame.outliers.push_back(false);
    }
    const KeyframeId keyframe = AddKeyframe(&map_, 0.0, Rigid3());
    history_.Record(map_, frame, keyframe, true, std::nullopt);
  }

  int Refine() { return history_.RefineAgainstMap(map_, intrinsics_, {{}, 10, 0.5}); }
  Rigid3 WorldFromCam() const { return history_.CurrentMapPoses(map_, true).at(0).world_from_cam; }

  Map map_;
  std::vector<MapPointId> points_;
  PinholeIntrinsics intrinsics_;
  PoseHistory history_{/*keep_matches=*/true, {}};
};

TEST_F(PoseHistoryRefinement, PutsAPoseBackOnThePointsItMatched) {
  EXPECT_EQ(Refine(), 1);
  ExpectSamePose(kTruth.Inverse(), WorldFromCam(), 1e-6);
  EXPECT_TRUE(history_.poses()[0].matches.empty());  // dropped once used
}

TEST_F(PoseHistoryRefinement, LeavesAPoseWhoseMatchedPointsAreMostlyGone) {
  map_.Write([&](MapData& data) {
    for (int i = 0; i < 16; ++i) data.EraseMapPoint(points_[i]);  // 14 of 30 left: < 50%
  });
  EXPECT_EQ(Refine(), 0);
  ExpectSamePose(kRecorded.Inverse(), WorldFromCam());
}

// A refined calibration reaches the kept matches: their pixels are what the new camera makes
// of the same raw pixels, and going back restores them.
TEST_F(PoseHistoryRefinement, KeptMatchesFollowARefinedCalibration) {
  CameraModel pinhole;
  pinhole.width = 640;
  pinhole.height = 480;
  pinhole.fx = pinhole.fy = 500.0;
  pinhole.cx = 320.0;
  pinhole.cy = 240.0;
  CameraModel radial = pinhole;
  radial.model = DistortionModel::kRadTan;
  radial.distortion[0] = 0.03;
  const std::vector<FrameMatch> before = history_.poses()[0].matches;
  ASSERT_EQ(before.size(), 30u);
  history_.Recalibrate(pinhole, radial);
  const std::vector<FrameMatch>& after = history_.poses()[0].matches;
  double largest_move = 0.0;
  for (std::size_t i = 0; i < before.size(); ++i) {
    const Eigen::Vector2d raw = before[i].pixel.cast<double>();  // pinhole: undistorted = raw
    const Eigen::Vector2d expected =
        Eigen::Vector2d(320.0, 240.0) + 500.0 * radial.Unproject(raw);
    EXPECT_LT((after[i].pixel.cast<double>() - expected).norm(), 1e-3) << i;
    largest_move = std::max(largest_move, double{(after[i].pixel - before[i].pixel).norm()});
  }
  EXPECT_GT(largest_move, 0.1);  // the correction moved the matches off-centre
  history_.Recalibrate(radial, pinhole);
  for (std::size_t i = 0; i < before.size(); ++i) {
    EXPECT_LT((history_.poses()[0].matches[i].pixel - before[i].pixel).norm(), 1e-3) << i;
  }
}

}  // namespace
}  // namespace arucoslam
