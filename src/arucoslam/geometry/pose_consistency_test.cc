#include "arucoslam/geometry/pose_consistency.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arucoslam {
namespace {

StampedPose At(double t, const Eigen::Vector3d& position) {
  return {t, Rigid3(Eigen::Quaterniond::Identity(), position)};
}

// A robot at 1 m/s on a circle of radius 0.9 m (the demo route's tight turn), 30 Hz frames.
Eigen::Vector3d OnTurn(double t) {
  const double angle = t / 0.9;
  return {0.9 * std::sin(angle), 0.9 * (1.0 - std::cos(angle)), 0.6};
}

TEST(PoseConsistency, FramesOnASmoothPathAreAllKept) {
  std::vector<StampedPose> frames, keyframes;
  for (int i = 0; i <= 90; ++i) frames.push_back(At(i / 30.0, OnTurn(i / 30.0)));
  for (int i = 0; i <= 90; i += 15) keyframes.push_back(At(i / 30.0, OnTurn(i / 30.0)));
  int dropped = -1;
  EXPECT_EQ(DropPosesOffTheirKeyframes(frames, keyframes, {}, &dropped).size(), frames.size());
  EXPECT_EQ(dropped, 0);
}

TEST(PoseConsistency, AFrameFarOffItsKeyframesIsDropped) {
  // Straight at 1 m/s, keyframes every 0.3 s (0.3 m apart: the bound is max(0.25, 0.3) m).
  std::vector<StampedPose> frames, keyframes;
  for (int i = 0; i <= 60; ++i) frames.push_back(At(i / 30.0, {i / 30.0, 0, 0}));
  for (int i = 0; i <= 60; i += 9) keyframes.push_back(At(i / 30.0, {i / 30.0, 0, 0}));
  frames[20].world_from_cam.translation.y() = 0.6;   // off: dropped
  frames[40].world_from_cam.translation.y() = -0.2;  // within the bound: kept
  int dropped = 0;
  const std::vector<StampedPose> kept = DropPosesOffTheirKeyframes(frames, keyframes, {}, &dropped);
  EXPECT_EQ(dropped, 1);
  ASSERT_EQ(kept.size(), frames.size() - 1);
  for (const StampedPose& pose : kept) EXPECT_NE(pose.timestamp_s, frames[20].timestamp_s);
  // The keyframes may come in any order.
  std::vector<StampedPose> reversed(keyframes.rbegin(), keyframes.rend());
  EXPECT_EQ(DropPosesOffTheirKeyframes(frames, reversed, {}).size(), kept.size());
}

TEST(PoseConsistency, FramesWithoutKeyframesCloseInTimeOnBothSidesAreKept) {
  std::vector<StampedPose> frames = {At(0.0, {5, 5, 5}), At(1.0, {9, 9, 9}), At(3.5, {7, 7, 7})};
  // Keyframes at 0.5 s and 2.0 s (1.5 s apart) and at 3.0 s: the first frame lies before
  // them, the second between keyframes too far apart in time, the last after them.
  const std::vector<StampedPose> keyframes = {At(0.5, {0, 0, 0}), At(2.0, {1.5, 0, 0}),
                                              At(3.0, {2.5, 0, 0})};
  int dropped = -1;
  EXPECT_EQ(DropPosesOffTheirKeyframes(frames, keyframes, {}, &dropped).size(), 3u);
  EXPECT_EQ(dropped, 0);
  PoseConsistencyOptions wider;
  wider.max_keyframe_gap_s = 2.0;  // now the second frame is checked, and 9 m off
  EXPECT_EQ(DropPosesOffTheirKeyframes(frames, keyframes, wider, &dropped).size(), 2u);
  EXPECT_EQ(dropped, 1);
}

}  // namespace
}  // namespace arucoslam
