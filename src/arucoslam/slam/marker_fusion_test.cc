// MarkerFusion on synthetic views of a board of four known markers (15 cm) on the plane z = 0,
// seen from a camera 2-3 m in front of it: locations against the true poses, one ambiguous
// marker settled by motion predictions, and keypoint poses judged against the markers.
#include "arucoslam/slam/marker_fusion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "arucoslam/markers/marker_pose.h"

namespace arucoslam {
namespace {

constexpr double kSide = 0.15;    // metres
constexpr double kNoisePx = 0.3;  // corner noise

CameraModel Camera() { return PinholeCamera(1280, 720, 1100.0); }

// Marker `id` (0-3) at a corner of a 0.6 x 0.4 m rectangle on z = 0, facing -z.
Rigid3 WorldFromMarker(int id) {
  const Eigen::Quaterniond facing(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  return Rigid3(facing, Eigen::Vector3d(id % 2 == 0 ? -0.3 : 0.3, id < 2 ? -0.2 : 0.2, 0.0));
}

MarkerMap Board() {
  MarkerMap map;
  for (int id = 0; id < 4; ++id) {
    MarkerInfo info;
    info.id = id;
    info.size = kSide;
    info.world_from_marker = WorldFromMarker(id);
    map.markers[id] = info;
  }
  return map;
}

// A camera `distance` metres from marker 0, `angle_deg` off its normal (about y), facing it.
Rigid3 ObliqueOnMarker0(double distance, double angle_deg) {
  const double angle = angle_deg * M_PI / 180.0;
  const Eigen::Vector3d target = WorldFromMarker(0).translation;
  const Eigen::Vector3d centre =
      target + distance * Eigen::Vector3d(std::sin(angle), 0.0, -std::cos(angle));
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(-angle, Eigen::Vector3d::UnitY())), centre);
}

// A camera at (x, y, -distance) looking along +z at the board, turned `yaw_deg` about y.
Rigid3 WorldFromCam(double x, double y, double distance, double yaw_deg = 0.0) {
  return Rigid3(
      Eigen::Quaterniond(Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d(x, y, -distance));
}

std::vector<MarkerDetection> Detect(const Rigid3& world_from_cam, const std::vector<int>& ids,
                                    std::mt19937& random) {
  std::normal_distribution<double> noise(0.0, kNoisePx);
  const Rigid3 cam_from_world = world_from_cam.Inverse();
  std::vector<MarkerDetection> detections;
  for (const int id : ids) {
    MarkerDetection detection;
    detection.id = id;
    const auto corners = SquareCorners(kSide);
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d in_cam = cam_from_world * (WorldFromMarker(id) * corners[c]);
      detection.corners[c] =
          *Camera().Project(in_cam) + Eigen::Vector2d(noise(random), noise(random));
    }
    detections.push_back(detection);
  }
  return detections;
}

MarkerFusion MakeFusion(const MarkerFusionOptions& options = {}) {
  return MarkerFusion(options, Camera(), Board(), kSide);
}

double Degrees(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return RotationAngle(a.inverse() * b) * 180.0 / M_PI;
}

Frame TrackedFrame(double timestamp_s, const Rigid3& world_from_cam) {
  Frame frame;
  frame.timestamp_s = timestamp_s;
  frame.cam_from_world = world_from_cam.Inverse();
  return frame;
}

// The same pose with its camera centre moved `dx` metres along x.
Rigid3 Shifted(const Rigid3& world_from_cam, double dx) {
  Rigid3 shifted = world_from_cam;
  shifted.translation.x() += dx;
  return shifted;
}

// Marker 0 alone seen from `world_from_cam` (3 m away, 20 sides, 20 degrees off its normal:
// IPPE's two solutions explain its corners about as well) and that true pose; the view is
// kept when its location is ambiguous between solutions more than 10 degrees apart.
struct AmbiguousView {
  Rigid3 world_from_cam;
  std::vector<MarkerDetection> detections;
};

AmbiguousView FindAmbiguousView(const Rigid3& world_from_cam, std::mt19937& random) {
  for (int attempt = 0; attempt < 50; ++attempt) {
    AmbiguousView view{world_from_cam, Detect(world_from_cam, {0}, random)};
    const CameraLocation location = LocateCamera(view.detections, Board(), Camera());
    if (location.found && location.quality.ambiguous && location.alternative_world_from_cam &&
        Degrees(location.world_from_cam.rotation, location.alternative_world_from_cam->rotation) >
            10.0) {
      return view;
    }
  }
  ADD_FAILURE() << "no ambiguous view of one marker";
  return {};
}

TEST(MarkerFusionTest, LocatesTheCameraFromSeveralMarkers) {
  std::mt19937 random(1);
  MarkerFusion fusion = MakeFusion();
  const Rigid3 truth = WorldFromCam(0.2, -0.1, 2.0, 8.0);
  const std::optional<MarkerFix>& fix =
      fusion.Locate(Detect(truth, {0, 1, 2, 3}, random), Board(), 0.0, {}, 0);
  ASSERT_TRUE(fix);
  EXPECT_LT((fix->world_from_cam.translation - truth.translation).norm(), 0.01);
  EXPECT_LT(Degrees(fix->world_from_cam.rotation, truth.rotation), 0.5);
  EXPECT_EQ(fusion.num_markers(), 4);
  EXPECT_EQ(fix->markers.size(), 4u);
  EXPECT_TRUE(fix->known_markers_only);
  EXPECT_FALSE(fix->settled_ambiguity);
  // Its corners' information: millimetres to centimetres 2 m from the board, and the located
  // centre within three of its standard deviations of the truth.
  const double sigma = LeastCertainPositionSigma(fix->corner_information);
  EXPECT_GT(sigma, 1e-3);
  EXPECT_LT(sigma, 0.05);
  EXPECT_LT((fix->world_from_cam.translation - truth.translation).norm(), 3.0 * sigma);
  // The fix's markers carry their world poses and the corners as seen (no distortion here).
  EXPECT_LT((fix->markers[0].world_from_marker.translation - WorldFromMarker(0).translation).norm(),
            1e-12);
  EXPECT_EQ(fusion.stats().num_located_frames, 1);
}

TEST(MarkerFusionTest, MarkersMappedDuringTheRunAreNotKnownOnly) {
  std::mt19937 random(2);
  // Marker 3 is not in the fixed map: it was mapped during the run.
  MarkerMap fixed = Board();
  fixed.markers.erase(3);
  MarkerFusion fusion(MarkerFusionOptions(), Camera(), fixed, kSide);
  MarkerMap locating = Board();
  locating.markers[3].fixed = false;
  const Rigid3 truth = WorldFromCam(0.0, 0.0, 2.0);
  ASSERT_TRUE(fusion.Locate(Detect(truth, {0, 1, 2, 3}, random), locating, 0.0, {}, 0));
  EXPECT_FALSE(fusion.fix()->known_markers_only);
  ASSERT_TRUE(fusion.Locate(Detect(truth, {0, 1, 2}, random), locating, 0.1, {}, 1));
  EXPECT_TRUE(fusion.fix()->known_markers_only);
}

TEST(MarkerFusionTest, FarOrPoorlyFittingLocationsAreNotUsed) {
  std::mt19937 random(3);
  // 5 m is 33 marker sides: beyond max_marker_distance_sides (25).
  MarkerFusion fusion = MakeFusion();
  EXPECT_FALSE(fusion.Locate(Detect(WorldFromCam(0.0, 0.0, 5.0), {0, 1, 2, 3}, random), Board(),
                             0.0, {}, 0));
  EXPECT_EQ(fusion.num_markers(), 4);  // located, but not usable
  // The same view with a corner RMS bound below the noise.
  MarkerFusionOptions strict;
  strict.max_marker_rms_px = 0.05;
  MarkerFusion strict_fusion = MakeFusion(strict);
  EXPECT_FALSE(strict_fusion.Locate(Detect(WorldFromCam(0.0, 0.0, 2.0), {0, 1, 2, 3}, random),
                                    Board(), 0.0, {}, 0));
  EXPECT_EQ(strict_fusion.stats().num_located_frames, 0);
}

TEST(MarkerFusionTest, AmbiguousMarkerWithoutPredictionIsNotUsed) {
  std::mt19937 random(4);
  MarkerFusion fusion = MakeFusion();
  const AmbiguousView view = FindAmbiguousView(ObliqueOnMarker0(3.0, 20.0), random);
  EXPECT_FALSE(fusion.Locate(view.detections, Board(), 0.0, {}, 0));
  EXPECT_EQ(fusion.num_markers(), 1);
  EXPECT_EQ(fusion.stats().num_disambiguations, 0);
}

TEST(MarkerFusionTest, AmbiguousMarkerIsSettledByTheAlignedTrackersPrediction) {
  std::mt19937 random(5);
  const AmbiguousView view = FindAmbiguousView(ObliqueOnMarker0(3.0, 20.0), random);
  MapPrediction map;
  map.world_aligned = true;
  map.tracking = true;
  // The tracker predicts the pose 5 cm and 1 degree off the truth.
  const Rigid3 predicted(
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d::UnitX())) *
          view.world_from_cam.rotation,
      view.world_from_cam.translation + Eigen::Vector3d(0.05, 0.0, 0.0));
  map.predicted_cam_from_map = predicted.Inverse();
  MarkerFusion fusion = MakeFusion();
  const std::optional<MarkerFix>& fix = fusion.Locate(view.detections, Board(), 0.0, map, 0);
  ASSERT_TRUE(fix);
  EXPECT_TRUE(fix->settled_ambiguity);
  // The true solution, within what one marker 20 sides away allows (the mirrored one lies
  // metres away).
  EXPECT_LT((fix->world_from_cam.translation - view.world_from_cam.translation).norm(), 0.2);
  EXPECT_LT(Degrees(fix->world_from_cam.rotation, view.world_from_cam.rotation), 3.0);
  EXPECT_EQ(fusion.stats().num_disambiguations, 1);
  EXPECT_EQ(fusion.stats().num_map_rotation_disambiguations, 0);

  // A prediction far from both solutions settles nothing.
  map.predicted_cam_from_map = Shifted(view.world_from_cam, 1.0).Inverse();
  MarkerFusion other = MakeFusion();
  EXPECT_FALSE(other.Locate(view.detections, Board(), 0.0, map, 0));
  // Nor does a correct prediction with the motion rule off.
  MarkerFusionOptions off;
  off.resolve_ambiguity_by_motion = false;
  MarkerFusion no_motion = MakeFusion(off);
  map.predicted_cam_from_map = predicted.Inverse();
  EXPECT_FALSE(no_motion.Locate(view.detections, Board(), 0.0, map, 0));
}

TEST(MarkerFusionTest, AmbiguousMarkerIsSettledByTheRecentFixesMotion) {
  std::mt19937 random(6);
  MarkerFusion fusion = MakeFusion();
  // The camera moves sideways at 0.5 m/s, seeing the whole board at 10 Hz ...
  const auto pose_at = [](double t) {
    return Shifted(ObliqueOnMarker0(3.0, 20.0), 0.5 * (t - 0.6));
  };
  for (int i = 0; i < 6; ++i) {
    const double t = 0.1 * i;
    ASSERT_TRUE(fusion.Locate(Detect(pose_at(t), {0, 1, 2, 3}, random), Board(), t, {}, i));
  }
  // ... then only marker 0, ambiguous: the fixes' constant velocity predicts the pose.
  const double t = 0.6;
  const AmbiguousView view = FindAmbiguousView(pose_at(t), random);
  const std::optional<MarkerFix>& fix = fusion.Locate(view.detections, Board(), t, {}, 6);
  ASSERT_TRUE(fix);
  EXPECT_TRUE(fix->settled_ambiguity);
  EXPECT_LT((fix->world_from_cam.translation - pose_at(t).translation).norm(), 0.2);
  EXPECT_LT(Degrees(fix->world_from_cam.rotation, pose_at(t).rotation), 3.0);
  EXPECT_EQ(fusion.stats().num_located_frames, 7);
  EXPECT_EQ(fusion.stats().num_disambiguations, 1);

  // A second later the fixes are too old to predict.
  const AmbiguousView late = FindAmbiguousView(pose_at(t + 1.0), random);
  EXPECT_FALSE(fusion.Locate(late.detections, Board(), t + 1.0, {}, 7));
}

TEST(MarkerFusionTest, AmbiguousMarkerIsSettledByTheUnalignedMapsVotedOrientation) {
  std::mt19937 random(9);
  MarkerFusion fusion = MakeFusion();
  // A keypoint map not aligned yet: its frame is the world turned 30 degrees about z and
  // shifted (its scale does not matter to orientations).
  const Rigid3 world_from_map(
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 6.0, Eigen::Vector3d::UnitZ())),
      Eigen::Vector3d(1.0, -2.0, 0.5));
  MapPrediction map;
  map.tracking = true;
  // The map tracks the camera as it swings round marker 0 (12 to 34 degrees off its
  // normal): each ambiguous view votes for the world's orientation once tracked; the true
  // solutions agree on it, the mirrored ones wander.
  for (int k = 0; k < 12; ++k) {
    const AmbiguousView view = FindAmbiguousView(ObliqueOnMarker0(3.0, 12.0 + 2.0 * k), random);
    EXPECT_FALSE(fusion.Locate(view.detections, Board(), 0.1 * k, map, k)) << k;
    fusion.NoteTrackedFrame(TrackedFrame(0.1 * k, world_from_map.Inverse() * view.world_from_cam),
                            false);
  }
  // The next ambiguous view is settled by the orientation the map predicts for it.
  const AmbiguousView view = FindAmbiguousView(ObliqueOnMarker0(3.0, 25.0), random);
  map.predicted_cam_from_map = (world_from_map.Inverse() * view.world_from_cam).Inverse();
  const std::optional<MarkerFix>& fix = fusion.Locate(view.detections, Board(), 1.2, map, 12);
  ASSERT_TRUE(fix);
  EXPECT_LT(Degrees(fix->world_from_cam.rotation, view.world_from_cam.rotation), 3.0);
  EXPECT_LT((fix->world_from_cam.translation - view.world_from_cam.translation).norm(), 0.2);
  EXPECT_EQ(fusion.stats().num_map_rotation_disambiguations, 1);
  // A new map starts a new vote: the same prediction later (the fixes too old to predict)
  // settles nothing.
  fusion.MapReset();
  EXPECT_FALSE(fusion.Locate(view.detections, Board(), 3.0, map, 13));
}

class MarkerFusionVerdictTest : public ::testing::Test {
 protected:
  // Locates the frame at `t` from the whole board at the true pose, in a world-aligned map.
  void LocateAt(double t) {
    MapPrediction map;
    map.world_aligned = true;
    ASSERT_TRUE(fusion_.Locate(Detect(truth_, {0, 1, 2, 3}, random_), Board(), t, map, 0));
  }
  PoseVerdict Judge(double t, double dx) {
    return fusion_.JudgeTrackedPose(TrackedFrame(t, Shifted(truth_, dx)), true, 0);
  }

  std::mt19937 random_{7};
  Rigid3 truth_ = WorldFromCam(0.1, 0.0, 2.0);
  MarkerFusion fusion_ = MakeFusion();
};

TEST_F(MarkerFusionVerdictTest, KeypointPoseFarFromTheMarkersIsRejected) {
  fusion_.MapEnteredWorld();
  LocateAt(0.1);
  EXPECT_EQ(Judge(0.1, 0.2), PoseVerdict::kAccepted);  // within 0.5 m
  EXPECT_TRUE(fusion_.Confirms(Shifted(truth_, 0.2).Inverse()));
  // 1 m off: a look-alike place.
  EXPECT_EQ(Judge(0.1, 1.0), PoseVerdict::kRejected);
  EXPECT_FALSE(fusion_.Confirms(Shifted(truth_, 1.0).Inverse()));
  EXPECT_EQ(fusion_.stats().num_rejected_poses, 1);
  // Outside the marker world nothing is judged.
  EXPECT_EQ(fusion_.JudgeTrackedPose(TrackedFrame(0.1, Shifted(truth_, 1.0)), false, 0),
            PoseVerdict::kAccepted);
}

TEST_F(MarkerFusionVerdictTest, WithoutMarkerLocationEveryPoseIsAccepted) {
  fusion_.MapEnteredWorld();
  MapPrediction map;
  map.world_aligned = true;
  EXPECT_FALSE(fusion_.Locate({}, Board(), 0.1, map, 0));
  EXPECT_EQ(Judge(0.1, 5.0), PoseVerdict::kAccepted);
  EXPECT_FALSE(fusion_.Confirms(truth_.Inverse()));  // and no relocalisation is confirmed
}

TEST_F(MarkerFusionVerdictTest, DisagreementIsRejectedHoweverLongAfterTheMarkersAgreed) {
  fusion_.MapEnteredWorld();
  LocateAt(0.0);
  EXPECT_EQ(Judge(0.0, 0.4), PoseVerdict::kAccepted);  // within the 0.5 m gate
  // 0.1 s later the offset has grown to 0.6 m, 3 s later it is 0.8 m: each beyond the gate,
  // each rejected; the map's drift is corrected only by keyframes within the gate.
  LocateAt(0.1);
  EXPECT_EQ(Judge(0.1, 0.6), PoseVerdict::kRejected);
  LocateAt(3.0);
  EXPECT_EQ(Judge(3.0, 0.8), PoseVerdict::kRejected);
  EXPECT_EQ(fusion_.stats().num_rejected_poses, 2);
  // A wider gate accepts the same pose.
  MarkerFusionOptions wide;
  wide.max_marker_disagreement_m = 1.0;
  MarkerFusion lenient = MakeFusion(wide);
  MapPrediction map;
  map.world_aligned = true;
  ASSERT_TRUE(lenient.Locate(Detect(truth_, {0, 1, 2, 3}, random_), Board(), 3.0, map, 0));
  EXPECT_EQ(lenient.JudgeTrackedPose(TrackedFrame(3.0, Shifted(truth_, 0.8)), true, 0),
            PoseVerdict::kAccepted);
}

TEST(MarkerFusionTest, LocatesInAnotherMapWithTheFramesEarlierPose) {
  std::mt19937 random(8);
  const MarkerFusion fusion = MakeFusion();
  const Rigid3 truth = WorldFromCam(0.2, 0.1, 2.0, -5.0);
  std::vector<MarkerObservation> board;
  for (const MarkerDetection& detection : Detect(truth, {0, 1, 2, 3}, random)) {
    board.push_back({MarkerId(detection.id), detection.corners});
  }
  const std::optional<Rigid3> located = fusion.LocateInMap(board, Board(), std::nullopt);
  ASSERT_TRUE(located);
  EXPECT_LT((located->Inverse().translation - truth.translation).norm(), 0.01);

  // One ambiguous marker: settled by the frame's earlier pose, unused without one.
  const AmbiguousView view = FindAmbiguousView(ObliqueOnMarker0(3.0, 20.0), random);
  const std::vector<MarkerObservation> one = {{MarkerId(0), view.detections[0].corners}};
  EXPECT_FALSE(fusion.LocateInMap(one, Board(), std::nullopt));
  const std::optional<Rigid3> settled =
      fusion.LocateInMap(one, Board(), Shifted(view.world_from_cam, 0.05).Inverse());
  ASSERT_TRUE(settled);
  EXPECT_LT((settled->Inverse().translation - view.world_from_cam.translation).norm(), 0.2);
}

TEST(MarkerFusionTest, OptionsSayWhatIsWrong) {
  MarkerFusionOptions options;
  EXPECT_TRUE(options.Check());
  std::string why;
  options.max_marker_rms_px = 0.0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("max_marker_rms_px"), std::string::npos) << why;
  options = {};
  options.rotation_vote.min_support = 1;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("rotation_vote.min_support"), std::string::npos) << why;
  options = {};
  options.max_marker_disagreement_m = 0.0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("max_marker_disagreement_m"), std::string::npos) << why;
}

}  // namespace
}  // namespace arucoslam
