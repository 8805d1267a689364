// WorldAnchoring on keyframes whose map frame is the world scaled by 1/2, turned 30 degrees
// about z and shifted: when the map is aligned and realigned, which anchor sets are refused,
// and when a keyframe's marker location asks for a drift correction.
#include "arucoslam/slam/world_anchoring.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "arucoslam/geometry/pose_information.h"

namespace arucoslam {
namespace {

const Sim3 kMapFromWorld(0.5,
                         Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ())),
                         Eigen::Vector3d(0.3, -0.2, 0.1));

// Camera `i` of a walk through the world: centres on a 2 x 1 m rectangle's border at 1.5 m
// height, each turned a little more about z.
Rigid3 WorldFromCam(int i) {
  const double t = 0.37 * i;
  const Eigen::Vector3d centre(2.0 * std::cos(t), std::sin(t), 1.5 + 0.1 * std::sin(3.0 * t));
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * i, Eigen::Vector3d::UnitZ())), centre);
}

// A keyframe at the true world pose, expressed in the map frame.
KeyframeId AddKeyframe(const Rigid3& world_from_cam, Map* map) {
  Keyframe keyframe;
  keyframe.cam_from_world = kMapFromWorld.TransformPose(world_from_cam).Inverse();
  return map->Write([&](MapData& data) { return data.AddKeyframe(keyframe); });
}

// A marker location of one known marker, `shift` off the truth, whose corners fix the camera
// centre to `corner_sigma_m` (and its rotation to 5 mrad).
MarkerFix Fix(const Rigid3& world_from_cam, const Eigen::Vector3d& shift = Eigen::Vector3d::Zero(),
              double corner_sigma_m = 0.005) {
  MarkerFix fix;
  fix.world_from_cam = world_from_cam;
  fix.world_from_cam.translation += shift;
  fix.markers.resize(1);
  fix.corner_information = IsotropicPoseInformation(corner_sigma_m, 0.005);
  return fix;
}

// Keyframes first..last-1 of the walk added to `map` and anchored.
void AddAnchors(int first, int last, Map* map, WorldAnchoring* anchoring) {
  for (int i = first; i < last; ++i) {
    anchoring->AddAnchor(AddKeyframe(WorldFromCam(i), map), Fix(WorldFromCam(i)));
  }
}

TEST(WorldAnchoring, AlignsWithFourAnchorsSpanningHalfAMetreNotThree) {
  Map map;
  WorldAnchoring anchoring({});
  AddAnchors(0, 3, &map, &anchoring);
  EXPECT_FALSE(anchoring.DecideAlignment(map).has_value());
  AddAnchors(3, 4, &map, &anchoring);
  const std::optional<AlignmentDecision> decision = anchoring.DecideAlignment(map);
  ASSERT_TRUE(decision.has_value());
  EXPECT_EQ(decision->anchors.size(), 4u);
  EXPECT_NEAR(decision->alignment.world_from_map.scale, 2.0, 1e-6);
  EXPECT_LT(decision->alignment.rms_m, 1e-6);
  EXPECT_FALSE(anchoring.aligned());
  Keyframe with_marker;
  with_marker.markers.resize(1);
  EXPECT_TRUE(anchoring.KeepsKeyframe(with_marker));
  EXPECT_FALSE(anchoring.KeepsKeyframe(Keyframe()));
  anchoring.AlignmentApplied(*decision);
  EXPECT_TRUE(anchoring.aligned());
  EXPECT_FALSE(anchoring.KeepsKeyframe(with_marker));
}

TEST(WorldAnchoring, ShortBaselineWaits) {
  Map map;
  WorldAnchoring anchoring({});
  for (int i = 0; i < 6; ++i) {  // centres within 0.4 m
    Rigid3 world_from_cam = WorldFromCam(0);
    world_from_cam.translation.x() += 0.08 * i;
    anchoring.AddAnchor(AddKeyframe(world_from_cam, &map), Fix(world_from_cam));
  }
  EXPECT_FALSE(anchoring.DecideAlignment(map).has_value());
}

TEST(WorldAnchoring, RealignsWhenTheAnchorsDouble) {
  Map map;
  WorldAnchoring anchoring({});
  AddAnchors(0, 4, &map, &anchoring);
  anchoring.AlignmentApplied(*anchoring.DecideAlignment(map));
  AddAnchors(4, 7, &map, &anchoring);
  EXPECT_FALSE(anchoring.DecideAlignment(map).has_value());
  AddAnchors(7, 8, &map, &anchoring);
  const std::optional<AlignmentDecision> again = anchoring.DecideAlignment(map);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->anchors.size(), 8u);
  anchoring.AlignmentApplied(*again);
  EXPECT_EQ(anchoring.stats().num_alignments, 2);
  // No more anchors are collected once realignment stopped.
  anchoring.StopRealigning();
  AddAnchors(8, 20, &map, &anchoring);
  EXPECT_FALSE(anchoring.DecideAlignment(map).has_value());
}

TEST(WorldAnchoring, AnchorsWhoseKeyframeLeftTheMapAreForgotten) {
  Map map;
  WorldAnchoring anchoring({});
  anchoring.AddAnchor(KeyframeId(1000), Fix(WorldFromCam(0)));  // not in the map
  AddAnchors(1, 4, &map, &anchoring);
  EXPECT_FALSE(anchoring.DecideAlignment(map).has_value());  // 3 of 4 have keyframes
  AddAnchors(4, 5, &map, &anchoring);
  ASSERT_TRUE(anchoring.DecideAlignment(map).has_value());
}

TEST(WorldAnchoring, ResidualAboveMaxRmsIsRefused) {
  Map map;
  WorldAnchoringOptions options;
  options.max_alignment_rms_m = 0.02;
  WorldAnchoring strict(options);
  WorldAnchoring lenient({});
  for (int i = 0; i < 6; ++i) {  // marker locations 5 cm off, in alternating directions
    const KeyframeId id = AddKeyframe(WorldFromCam(i), &map);
    const Eigen::Vector3d shift(0.0, 0.0, i % 2 == 0 ? 0.05 : -0.05);
    strict.AddAnchor(id, Fix(WorldFromCam(i), shift));
    lenient.AddAnchor(id, Fix(WorldFromCam(i), shift));
  }
  EXPECT_FALSE(strict.DecideAlignment(map).has_value());
  const std::optional<AlignmentDecision> decision = lenient.DecideAlignment(map);
  ASSERT_TRUE(decision.has_value());
  EXPECT_GT(decision->alignment.rms_m, 0.02);
  EXPECT_LT(decision->alignment.rms_m, 0.15);
}

TEST(WorldAnchoring, DriftIsCorrectedBeyondFiveCentimetresAndThreeSigmas) {
  Map map;
  WorldAnchoring anchoring({});
  AddAnchors(0, 4, &map, &anchoring);
  // Keypoint poses 4 cm and 20 cm from their marker locations.
  const KeyframeId near = AddKeyframe(WorldFromCam(4), &map);
  anchoring.AddAnchor(near, Fix(WorldFromCam(4), Eigen::Vector3d(0.04, 0.0, 0.0)));
  const KeyframeId far = AddKeyframe(WorldFromCam(5), &map);
  anchoring.AddAnchor(far, Fix(WorldFromCam(5), Eigen::Vector3d(0.2, 0.0, 0.0)));
  const KeyframeId seen_far = AddKeyframe(WorldFromCam(6), &map);  // for a far marker below
  anchoring.AlignmentApplied(*anchoring.DecideAlignment(map));
  // The map frame is the world now.
  map.Write([](MapData& data) {
    ApplyWorldAlignment(kMapFromWorld.Inverse(), &data);
    return 0;
  });
  EXPECT_FALSE(anchoring.DecideDriftCorrection(map, near).has_value());
  const std::optional<DriftCorrectionDecision> decision = anchoring.DecideDriftCorrection(map, far);
  ASSERT_TRUE(decision.has_value());
  EXPECT_NEAR(decision->offset_m, 0.2, 1e-6);
  // 20 cm over the corners' 5 mm and the 1 cm floor of one marker: sqrt(0.005^2 + 0.01^2).
  EXPECT_NEAR(decision->offset_sigmas, 0.2 / std::sqrt(0.005 * 0.005 + 0.01 * 0.01), 1e-6);
  EXPECT_EQ(decision->priors.size(), 6u);
  // A prior of 10 cm: 20 cm is within three sigmas.
  WorldAnchoringOptions loose;
  loose.marker_priors.prior_position_sigma_m = 0.1;
  WorldAnchoring loose_anchoring(loose);
  loose_anchoring.AddKeyframeFixes(anchoring.KeyframeFixes());
  EXPECT_NEAR(LeastCertainPositionSigma(loose_anchoring.KnownMarkerPriors()[0].information),
              std::sqrt(0.005 * 0.005 + 0.1 * 0.1), 1e-9);
  EXPECT_FALSE(loose_anchoring.DecideDriftCorrection(map, far).has_value());
  // A far marker whose corners fix the centre to 10 cm: 20 cm is within three sigmas too.
  WorldAnchoring far_marker_anchoring({});
  far_marker_anchoring.AddAnchor(seen_far,
                                 Fix(WorldFromCam(6), Eigen::Vector3d(0.2, 0.0, 0.0), 0.1));
  EXPECT_FALSE(far_marker_anchoring.DecideDriftCorrection(map, seen_far).has_value());
  far_marker_anchoring.AddAnchor(far, Fix(WorldFromCam(5), Eigen::Vector3d(0.2, 0.0, 0.0)));
  EXPECT_TRUE(far_marker_anchoring.DecideDriftCorrection(map, far).has_value());
  // Switched off: no correction, however far.
  WorldAnchoringOptions off;
  off.drift_correction = false;
  WorldAnchoring off_anchoring(off);
  off_anchoring.AddKeyframeFixes(anchoring.KeyframeFixes());
  EXPECT_FALSE(off_anchoring.DecideDriftCorrection(map, far).has_value());
  // The corrections made are counted, with the alignments.
  anchoring.DriftCorrected();
  EXPECT_EQ(anchoring.stats().num_drift_corrections, 1);
  EXPECT_EQ(anchoring.stats().num_alignments, 1);
}

TEST(WorldAnchoring, MappedMarkersAndOutliersGiveNoPrior) {
  Map map;
  WorldAnchoring anchoring({});
  AddAnchors(0, 5, &map, &anchoring);
  MarkerFix mapped = Fix(WorldFromCam(5), Eigen::Vector3d(0.5, 0.0, 0.0));
  mapped.known_markers_only = false;
  const KeyframeId id = AddKeyframe(WorldFromCam(5), &map);
  anchoring.AddAnchor(id, mapped);
  EXPECT_EQ(anchoring.KnownMarkerPriors().size(), 5u);
  EXPECT_FALSE(anchoring.DecideDriftCorrection(map, id).has_value());
  // An anchor 1 m off is an outlier of the alignment and loses its prior.
  WorldAnchoring with_outlier({});
  Map outlier_map;
  AddAnchors(0, 5, &outlier_map, &with_outlier);
  with_outlier.AddAnchor(AddKeyframe(WorldFromCam(5), &outlier_map),
                         Fix(WorldFromCam(5), Eigen::Vector3d(1.0, 0.0, 0.0)));
  const std::optional<AlignmentDecision> decision = with_outlier.DecideAlignment(outlier_map);
  ASSERT_TRUE(decision.has_value());
  EXPECT_EQ(decision->alignment.num_inliers, 5);
  with_outlier.DropOutlierFixes(*decision);
  EXPECT_EQ(with_outlier.KnownMarkerPriors().size(), 5u);
  with_outlier.Reset();
  EXPECT_TRUE(with_outlier.KnownMarkerPriors().empty());
  EXPECT_FALSE(with_outlier.aligned());
}

TEST(WorldAnchoring, CheckNamesTheBadField) {
  std::string why;
  EXPECT_TRUE(WorldAnchoringOptions{}.Check(&why)) << why;
  WorldAnchoringOptions options;
  options.min_alignment_anchors = 1;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("min_alignment_anchors"), std::string::npos) << why;
  options = {};
  options.max_realignment_anchors = 3;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("max_realignment_anchors"), std::string::npos) << why;
  options = {};
  options.max_alignment_rms_m = 0.0;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("max_alignment_rms_m"), std::string::npos) << why;
}

}  // namespace
}  // namespace arucoslam
