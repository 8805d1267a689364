#include "arucoslam/slam/keyframe_policy.h"

#include <gtest/gtest.h>

#include "arucoslam/geometry/camera.h"

namespace arucoslam {
namespace {

KeyframeDecisionInput Input(int since, int tracked, int reference, bool idle, bool room = true) {
  KeyframeDecisionInput input;
  input.frames_since_last_keyframe = since;
  input.num_tracked = tracked;
  input.num_reference_tracked = reference;
  input.mapper_idle = idle;
  input.mapper_has_room = room;
  input.num_map_keyframes = 100;  // past the young-map rule
  return input;
}

TEST(KeyframePolicy, OptionsCheck) {
  EXPECT_TRUE(KeyframePolicyOptions().Check());
  KeyframePolicyOptions options;
  options.max_frames_between = options.min_frames_between - 1;
  EXPECT_FALSE(options.Check());
  options = {};
  options.tracked_ratio = 1.5;
  EXPECT_FALSE(options.Check());
}

TEST(KeyframePolicy, RatioAgainstReferenceDecidesWhenMapperIdle) {
  KeyframePolicyOptions options;
  options.min_frames_between = 2;
  // 0.9 x 200 = 180: 179 tracked asks for a keyframe, 180 does not.
  EXPECT_TRUE(DecideKeyframe(options, Input(2, 179, 200, true)).insert);
  EXPECT_FALSE(DecideKeyframe(options, Input(2, 180, 200, true)).insert);
  // Too soon after the last keyframe.
  EXPECT_EQ(DecideKeyframe(options, Input(1, 100, 200, true)).reason, "too-soon");
  // Too few inliers for a reliable keyframe.
  EXPECT_EQ(DecideKeyframe(options, Input(5, 15, 200, true)).reason, "too-few");
  EXPECT_TRUE(DecideKeyframe(options, Input(5, 16, 200, true)).insert);
}

TEST(KeyframePolicy, BusyMapperDefersUntilMaxFramesAndQueueRoom) {
  KeyframePolicyOptions options;
  options.max_frames_between = 20;
  EXPECT_EQ(DecideKeyframe(options, Input(19, 100, 200, false)).reason, "busy");
  EXPECT_EQ(DecideKeyframe(options, Input(20, 100, 200, false)).reason, "max-frames");
  EXPECT_FALSE(DecideKeyframe(options, Input(20, 100, 200, false, false)).insert);
  // Even after max frames, a frame that still tracks most reference points is no keyframe.
  EXPECT_FALSE(DecideKeyframe(options, Input(40, 195, 200, true)).insert);
}

TEST(KeyframePolicy, WeakTrackingInsertsWithoutWaiting) {
  KeyframePolicyOptions options;
  options.min_frames_between = 4;
  options.weak_ratio = 0.5;
  options.weak_tracked_points = 100;
  options.weak_min_frames_between = 1;
  // Normal ratio drop: waits for min_frames_between.
  EXPECT_EQ(DecideKeyframe(options, Input(1, 150, 200, true)).reason, "too-soon");
  EXPECT_EQ(DecideKeyframe(options, Input(4, 150, 200, true)).reason, "ratio");
  // Below half the reference's points, or below 100 inliers: the next frame already.
  EXPECT_EQ(DecideKeyframe(options, Input(1, 99, 400, true)).reason, "weak");
  EXPECT_EQ(DecideKeyframe(options, Input(1, 120, 260, true)).reason, "weak");
  EXPECT_EQ(DecideKeyframe(options, Input(1, 130, 260, true)).reason, "too-soon");
  // Also with a busy mapper, but only when its queue has room.
  EXPECT_EQ(DecideKeyframe(options, Input(1, 99, 400, false)).reason, "weak");
  EXPECT_EQ(DecideKeyframe(options, Input(1, 99, 400, false, false)).reason, "busy");
  // Never the keyframe's own frame, and never with too few inliers.
  EXPECT_EQ(DecideKeyframe(options, Input(0, 99, 400, true)).reason, "too-soon");
  EXPECT_EQ(DecideKeyframe(options, Input(3, 15, 400, true)).reason, "too-few");
  options.weak_ratio = 0.95;  // above tracked_ratio
  EXPECT_FALSE(options.Check());
}

// Weak keyframes (turns) are spaced by weak_min_frames_between (3 by default), still before
// min_frames_between.
TEST(KeyframePolicy, WeakKeyframesAreSpaced) {
  KeyframePolicyOptions options;
  options.min_frames_between = 4;
  ASSERT_EQ(options.weak_min_frames_between, 3);
  EXPECT_EQ(DecideKeyframe(options, Input(1, 99, 400, true)).reason, "too-soon");
  EXPECT_EQ(DecideKeyframe(options, Input(2, 99, 400, true)).reason, "too-soon");
  EXPECT_EQ(DecideKeyframe(options, Input(3, 99, 400, true)).reason, "weak");
  EXPECT_EQ(DecideKeyframe(options, Input(2, 99, 400, false)).reason, "busy");
  options.weak_min_frames_between = 0;
  EXPECT_FALSE(options.Check());
}

TEST(KeyframePolicy, AYoungMapTakesNoKeyframeWhileTheMapperIsBusy) {
  KeyframePolicyOptions options;
  options.young_map_keyframes = 20;
  KeyframeDecisionInput weak = Input(5, 50, 400, false);  // weak tracking, room in the queue
  weak.num_map_keyframes = 20;
  EXPECT_FALSE(MayInsertKeyframe(options, weak));
  EXPECT_EQ(DecideKeyframe(options, weak).reason, "young-busy");
  weak.num_map_keyframes = 21;  // no longer young: a weak frame goes to the busy mapper's queue
  EXPECT_TRUE(MayInsertKeyframe(options, weak));
  EXPECT_EQ(DecideKeyframe(options, weak).reason, "weak");
  KeyframeDecisionInput idle = Input(5, 150, 200, true);
  idle.num_map_keyframes = 3;  // young but idle: the usual rules
  EXPECT_TRUE(MayInsertKeyframe(options, idle));
  EXPECT_EQ(DecideKeyframe(options, idle).reason, "ratio");
  options.young_map_keyframes = 0;  // no young-map rule
  weak.num_map_keyframes = 2;
  EXPECT_EQ(DecideKeyframe(options, weak).reason, "weak");
  options.young_map_keyframes = -1;
  EXPECT_FALSE(options.Check());
}

TEST(KeyframePolicy, InsertKeyframeLinksCovisibilityAndSpanningTree) {
  Map map;
  const CameraModel camera = PinholeCamera(640, 480, 500.0);
  Frame frame;
  frame.camera = camera;
  frame.features.keypoints.resize(10);
  frame.features.undistorted.assign(10, Eigen::Vector2d::Zero());
  frame.features.descriptors = cv::Mat::zeros(10, kOrbDescriptorBytes, CV_8U);
  frame.features.pyramid = ScalePyramid::Make(8, 1.2);
  frame.ResetMatches();
  frame.cam_from_world = Rigid3::Identity();
  const KeyframeId first = InsertKeyframe(map, frame, KeyframeId());
  std::vector<MapPointId> points;
  map.Write([&](MapData& data) {
    for (int i = 0; i < 6; ++i) {
      points.push_back(data.AddMapPoint(MapPoint()));
      data.AddObservation(first, i, points.back());
    }
    return 0;
  });
  // The new frame tracked 4 of the points; one of them was flagged an outlier.
  for (int i = 0; i < 4; ++i) frame.map_point_ids[i + 2] = points[i];
  frame.outliers[2] = true;
  const KeyframeId second = InsertKeyframe(map, frame, first);
  map.Read([&](const MapData& data) {
    EXPECT_EQ(data.covisibility().Weight(first, second), 3);
    EXPECT_EQ(data.covisibility().Parent(second), first);
    EXPECT_EQ(data.FindKeyframe(second)->NumMapPoints(), 3);
    EXPECT_EQ(ReferenceTrackedPoints(data, first, 2), 3);
    EXPECT_EQ(ReferenceTrackedPoints(data, first, 1), 6);
    EXPECT_EQ(data.CheckInvariants(), "");
    return 0;
  });
}

}  // namespace
}  // namespace arucoslam
