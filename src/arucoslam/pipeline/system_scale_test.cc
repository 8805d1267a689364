// The keypoint SLAM's scale over a long forward drive, with keypoints that carry no image
// bias: unbiased noise at the level their size gives, and exact descriptors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "arucoslam/geometry/umeyama.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/slam/synthetic_corridor.h"

namespace arucoslam {
namespace {

constexpr double kFrameRateHz = 30.0;

// A ground vehicle's camera 0.6 m above the floor driving down the corridor (world x) at
// 1.2 m/s, weaving 0.15 m and turning 2 degrees either way.
Rigid3 WorldFromCam(int frame) {
  const double t = frame / kFrameRateHz;
  Eigen::Matrix3d forward;  // camera z along world x, camera x along -y, camera y along -z
  forward.col(0) = -Eigen::Vector3d::UnitY();
  forward.col(1) = -Eigen::Vector3d::UnitZ();
  forward.col(2) = Eigen::Vector3d::UnitX();
  const Eigen::Matrix3d yaw =
      Eigen::AngleAxisd(0.04 * std::cos(0.7 * t), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return Rigid3(Eigen::Quaterniond(yaw * forward),
                Eigen::Vector3d(1.2 * t, 0.15 * std::sin(0.7 * t), 0.6));
}

// Estimated length per true metre over the frames of [begin_s, end_s): the inverse of the
// scale of the Sim(3) that fits the estimate to the truth there.
double EstimatePerTruth(const std::vector<StampedPose>& trajectory, double begin_s, double end_s) {
  std::vector<Eigen::Vector3d> estimated, truth;
  for (const StampedPose& pose : trajectory) {
    if (pose.timestamp_s < begin_s || pose.timestamp_s >= end_s) continue;
    estimated.push_back(pose.world_from_cam.translation);
    truth.push_back(
        WorldFromCam(static_cast<int>(std::lround(pose.timestamp_s * kFrameRateHz))).translation);
  }
  const std::optional<Sim3> truth_from_estimate =
      UmeyamaAlignment(estimated, truth, AlignmentKind::kSimilarity);
  return truth_from_estimate ? 1.0 / truth_from_estimate->scale : 0.0;
}

// With keypoints free of image bias the map keeps its scale over 36 m of forward driving
// (windows of 6 s at both ends): the shrink measured on rendered routes comes from the image
// measurements, not from initialisation, triangulation, tracking or local BA.
TEST(SystemScale, HoldsItsScaleDownALongCorridorWithUnbiasedKeypoints) {
  const CameraModel camera = PinholeCamera(640, 480, 460.0);
  SyntheticCorridor corridor(camera);
  System system(camera, SystemOptions());
  const int num_frames = 900;
  for (int frame = 0; frame < num_frames; ++frame) {
    system.ProcessFrame(
        corridor.MakeFrame(FrameId(frame), frame / kFrameRateHz, WorldFromCam(frame).Inverse()));
  }
  system.Finish();
  const std::vector<StampedPose> trajectory = system.Trajectory();
  const double duration_s = num_frames / kFrameRateHz;
  const double first = EstimatePerTruth(trajectory, 0.0, 6.0);
  const double last = EstimatePerTruth(trajectory, duration_s - 6.0, duration_s);
  std::printf(
      "%zu of %d frames posed, %zu keyframes; scale of the last 6 s against the first "
      "%+.2f%%\n",
      trajectory.size(), num_frames, system.map().NumKeyframes(), 100.0 * (last / first - 1.0));
  EXPECT_GE(trajectory.size(), static_cast<std::size_t>(0.97 * num_frames));
  ASSERT_GT(first, 0.0);
  EXPECT_LT(std::abs(last / first - 1.0), 0.03);
}

TEST(SystemScale, CorridorOptionsCheckNamesTheBadValue) {
  SyntheticCorridorOptions options;
  options.detect_probability = 0.0;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "detect_probability must be in (0, 1], is 0");
  EXPECT_THROW(SyntheticCorridor(PinholeCamera(640, 480, 460.0), options), std::invalid_argument);
}

}  // namespace
}  // namespace arucoslam
