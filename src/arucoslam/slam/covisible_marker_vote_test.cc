// CovisibleMarkerVote on synthetic views of one known marker and a board of unknown ones
// around it: a camera moving past them, its one-marker locations ambiguous.
#include "arucoslam/slam/covisible_marker_vote.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "arucoslam/markers/marker_pose.h"

namespace arucoslam {
namespace {

constexpr double kSize = 0.02;  // metres: small markers, seen from 0.4 m, are ambiguous

CameraModel Camera() {
  CameraModel camera;
  camera.width = 1280;
  camera.height = 720;
  camera.fx = camera.fy = 1100.0;
  camera.cx = 640.0;
  camera.cy = 360.0;
  return camera;
}

// Marker `id` on the plane z = 0 facing -z (towards the cameras), on a 5 x 5 grid of 5 cm.
Rigid3 WorldFromMarker(int id) {
  const Eigen::Quaterniond facing(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  return Rigid3(facing, Eigen::Vector3d(0.05 * (id % 5 - 2), 0.05 * (id / 5 - 2), 0.0));
}

// Camera `t` of a sweep 0.4 m in front of the board, looking at its centre.
Rigid3 WorldFromCam(int t) {
  const Eigen::Vector3d centre(0.15 * std::sin(0.3 * t), 0.08 * std::cos(0.2 * t), -0.4);
  const Eigen::Vector3d z = (-centre).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  Eigen::Matrix3d axes;
  axes.col(0) = x;
  axes.col(1) = z.cross(x);
  axes.col(2) = z;
  return Rigid3(Eigen::Quaterniond(axes), centre);
}

std::vector<MarkerDetection> Detect(int t, std::mt19937& random) {
  std::normal_distribution<double> noise(0.0, 0.3);
  const CameraModel camera = Camera();
  const Rigid3 cam_from_world = WorldFromCam(t).Inverse();
  std::vector<MarkerDetection> detections;
  for (int id = 0; id < 25; ++id) {
    MarkerDetection detection;
    detection.id = id;
    const auto corners = SquareCorners(kSize);
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d in_cam = cam_from_world * (WorldFromMarker(id) * corners[c]);
      detection.corners[c] = *camera.Project(in_cam) + Eigen::Vector2d(noise(random), noise(random));
    }
    detections.push_back(detection);
  }
  return detections;
}

MarkerMap KnownCentreMarker() {
  MarkerMap map;
  MarkerInfo info;
  info.id = 12;  // the board's centre
  info.size = kSize;
  info.world_from_marker = WorldFromMarker(12);
  map.markers[12] = info;
  return map;
}

TEST(CovisibleMarkerVoteTest, SettlesAmbiguousLocationsOnTheTrueSolution) {
  std::mt19937 random(4);
  const MarkerMap known = KnownCentreMarker();
  CovisibleMarkerVote vote;
  int ambiguous = 0, settled = 0, wrong = 0;
  for (int t = 0; t < 30; ++t) {
    const std::vector<MarkerDetection> detections = Detect(t, random);
    const CameraLocation location = LocateCamera(detections, known, Camera());
    ASSERT_TRUE(location.found) << t;
    if (!location.quality.ambiguous || !location.alternative_world_from_cam) continue;
    ++ambiguous;
    std::vector<MarkerDetection> unknown;
    for (const MarkerDetection& detection : detections) {
      if (detection.id != 12) unknown.push_back(detection);
    }
    const AmbiguityChoice choice = vote.Add(location, unknown, kSize, Camera());
    if (choice == AmbiguityChoice::kNone) continue;
    ++settled;
    // The chosen solution is the one nearer the true camera (a single small marker's
    // location is still centimetres off; the other solution decimetres).
    const Rigid3 chosen = *ChosenPose(location, choice);
    const Rigid3 other = *ChosenPose(location, choice == AmbiguityChoice::kBest
                                                   ? AmbiguityChoice::kAlternative
                                                   : AmbiguityChoice::kBest);
    const Eigen::Vector3d truth = WorldFromCam(t).translation;
    if ((chosen.translation - truth).norm() >= (other.translation - truth).norm()) ++wrong;
  }
  ASSERT_GT(ambiguous, 10);  // the test is about ambiguous locations
  EXPECT_GE(settled, ambiguous / 2);
  EXPECT_EQ(wrong, 0);
  EXPECT_LE(vote.NumFrames(), CovisibleMarkerVoteOptions().max_frames);
}

TEST(CovisibleMarkerVoteTest, WithoutOtherMarkersNothingIsSettled) {
  std::mt19937 random(5);
  const MarkerMap known = KnownCentreMarker();
  CovisibleMarkerVote vote;
  for (int t = 0; t < 10; ++t) {
    const CameraLocation location = LocateCamera(Detect(t, random), known, Camera());
    EXPECT_EQ(vote.Add(location, {}, kSize, Camera()), AmbiguityChoice::kNone);
  }
  EXPECT_EQ(vote.NumFrames(), 0);
}

TEST(CovisibleMarkerVoteTest, OptionsSayWhatIsWrong) {
  CovisibleMarkerVoteOptions options;
  EXPECT_TRUE(options.Check());
  options.min_votes = 0;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("min_votes"), std::string::npos) << why;
}

}  // namespace
}  // namespace arucoslam
