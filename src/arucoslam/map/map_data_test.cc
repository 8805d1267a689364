#include "arucoslam/map/map_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "arucoslam/map/map.h"

namespace arucoslam {
namespace {

Keyframe MakeKeyframe(int num_keypoints, const Eigen::Vector3d& center, std::uint32_t seed) {
  std::mt19937 random(seed);
  Keyframe keyframe;
  keyframe.cam_from_world = Rigid3(Eigen::Quaterniond::Identity(), -center);
  keyframe.features.pyramid = ScalePyramid::Make(8, 1.2);
  keyframe.features.descriptors = cv::Mat(num_keypoints, kOrbDescriptorBytes, CV_8U);
  for (int i = 0; i < num_keypoints; ++i) {
    cv::KeyPoint keypoint(10.0f + i, 20.0f, 31.0f);
    keypoint.octave = i % 3;
    keyframe.features.keypoints.push_back(keypoint);
    for (int b = 0; b < kOrbDescriptorBytes; ++b) {
      keyframe.features.descriptors.at<std::uint8_t>(i, b) = random() & 0xff;
    }
  }
  keyframe.map_point_ids.assign(num_keypoints, MapPointId());
  return keyframe;
}

MapPointId AddPoint(MapData& data, const Eigen::Vector3d& p) {
  MapPoint point;
  point.p_in_world = p;
  return data.AddMapPoint(point);
}

// Three keyframes; points 0..9 seen by k0 and k1, 5..14 by k1 and k2 (keypoint = point index).
struct Fixture {
  MapData data;
  std::vector<KeyframeId> keyframes;
  std::vector<MapPointId> points;

  Fixture() {
    for (int k = 0; k < 3; ++k) {
      keyframes.push_back(data.AddKeyframe(MakeKeyframe(20, Eigen::Vector3d(k, 0, 0), k)));
    }
    for (int j = 0; j < 15; ++j) points.push_back(AddPoint(data, Eigen::Vector3d(j, 1, 5)));
    for (int j = 0; j < 15; ++j) {
      if (j < 10) EXPECT_TRUE(data.AddObservation(keyframes[0], j, points[j]));
      EXPECT_TRUE(data.AddObservation(keyframes[1], j, points[j]));
      if (j >= 5) EXPECT_TRUE(data.AddObservation(keyframes[2], j, points[j]));
    }
  }
};

TEST(MapDataTest, ObservationsAndCovisibilityAreConsistent) {
  Fixture f;
  EXPECT_EQ(f.data.CheckInvariants(), "");
  const CovisibilityGraph& graph = f.data.covisibility();
  EXPECT_EQ(graph.Weight(f.keyframes[0], f.keyframes[1]), 10);
  EXPECT_EQ(graph.Weight(f.keyframes[1], f.keyframes[2]), 10);
  EXPECT_EQ(graph.Weight(f.keyframes[0], f.keyframes[2]), 5);
  EXPECT_EQ(f.data.FindMapPoint(f.points[7])->NumObservations(), 3);
  EXPECT_EQ(f.data.FindKeyframe(f.keyframes[2])->NumMapPoints(), 10);
  EXPECT_EQ(f.data.FirstKeyframe(), f.keyframes[0]);
  EXPECT_EQ(f.data.LastKeyframe(), f.keyframes[2]);
}

TEST(MapDataTest, AbsorbedPointsKeepTheirReferenceKeyframeUnderItsNewId) {
  // Both maps number their keyframes from the same start: the other map's reference ids
  // also name keyframes of the host, which a pose-graph correction would move the points by.
  Fixture host;
  MapData other;
  std::vector<KeyframeId> other_keyframes;
  for (int k = 0; k < 3; ++k) {
    other_keyframes.push_back(other.AddKeyframe(MakeKeyframe(20, Eigen::Vector3d(k, 0, 0), k)));
  }
  MapPoint created;
  created.p_in_world = Eigen::Vector3d(1, 1, 5);
  created.reference_keyframe = other_keyframes[2];
  const MapPointId point = other.AddMapPoint(created);
  ASSERT_TRUE(other.AddObservation(other_keyframes[1], 4, point));
  ASSERT_TRUE(other.AddObservation(other_keyframes[2], 4, point));
  ASSERT_EQ(other.CheckInvariants(), "");
  ASSERT_NE(std::count(host.keyframes.begin(), host.keyframes.end(), other_keyframes[2]), 0);
  AbsorbedIds ids;
  ASSERT_TRUE(host.data.Absorb(other, host.keyframes[1], &ids));
  EXPECT_EQ(host.data.CheckInvariants(), "");
  EXPECT_EQ(host.data.FindMapPoint(ids.points.at(point))->reference_keyframe,
            ids.keyframes.at(other_keyframes[2]));
}

TEST(MapDataTest, AbsorbAddsAnotherMapUnderNewIds) {
  Fixture host;
  Fixture other;
  other.data.SetKeyframePose(other.keyframes[2], Rigid3(Eigen::Quaterniond::Identity(),
                                                        Eigen::Vector3d(-7, 0, 0)));
  other.data.IncreaseFound(other.points[3], 4);
  AbsorbedIds ids;
  EXPECT_FALSE(host.data.Absorb(other.data, KeyframeId(99), &ids));
  EXPECT_EQ(host.data.NumKeyframes(), 3u);
  ASSERT_TRUE(host.data.Absorb(other.data, host.keyframes[1], &ids));
  EXPECT_EQ(host.data.CheckInvariants(), "");
  EXPECT_EQ(host.data.NumKeyframes(), 6u);
  EXPECT_EQ(host.data.NumMapPoints(), 30u);
  ASSERT_EQ(ids.keyframes.size(), 3u);
  ASSERT_EQ(ids.points.size(), 15u);
  const KeyframeId k0 = ids.keyframes.at(other.keyframes[0]);
  const KeyframeId k1 = ids.keyframes.at(other.keyframes[1]);
  const KeyframeId k2 = ids.keyframes.at(other.keyframes[2]);
  for (const KeyframeId& id : {k0, k1, k2}) {
    EXPECT_EQ(std::count(host.keyframes.begin(), host.keyframes.end(), id), 0);
  }
  // Observations and covisibility as in the other map; none across the two maps.
  const CovisibilityGraph& graph = host.data.covisibility();
  EXPECT_EQ(graph.Weight(k0, k1), 10);
  EXPECT_EQ(graph.Weight(k1, k2), 10);
  EXPECT_EQ(graph.Weight(k0, k2), 5);
  EXPECT_EQ(graph.Weight(k0, host.keyframes[0]), 0);
  const MapPoint* point = host.data.FindMapPoint(ids.points.at(other.points[3]));
  ASSERT_NE(point, nullptr);
  EXPECT_EQ(point->num_found, 5);
  EXPECT_EQ(point->observations.at(k1), 3);
  EXPECT_EQ(host.data.FindKeyframe(k1)->map_point_ids[3], ids.points.at(other.points[3]));
  EXPECT_DOUBLE_EQ(host.data.FindKeyframe(k2)->cam_from_world.translation.x(), -7.0);
  // The other map's tree hangs under the chosen keyframe; first and last stay.
  EXPECT_EQ(graph.Parent(k0), host.keyframes[1]);
  EXPECT_EQ(graph.Parent(k1), k0);
  EXPECT_EQ(graph.Parent(k2), k1);
  EXPECT_EQ(host.data.FirstKeyframe(), host.keyframes[0]);
  EXPECT_EQ(host.data.LastKeyframe(), host.keyframes[2]);
  // The absorbed keyframes behave as any other: erasing one re-parents its child.
  EXPECT_TRUE(host.data.EraseKeyframe(k1));
  EXPECT_EQ(host.data.CheckInvariants(), "");
}

TEST(MapDataTest, RejectsInvalidObservations) {
  Fixture f;
  EXPECT_FALSE(f.data.AddObservation(f.keyframes[0], 20, f.points[0]));  // index out of range
  EXPECT_FALSE(f.data.AddObservation(f.keyframes[0], -1, f.points[0]));
  EXPECT_FALSE(f.data.AddObservation(KeyframeId(99), 0, f.points[0]));
  EXPECT_FALSE(f.data.AddObservation(f.keyframes[0], 0, MapPointId(999)));
  EXPECT_EQ(f.data.CheckInvariants(), "");
}

TEST(MapDataTest, ReassigningASlotOrAPointMovesTheObservation) {
  Fixture f;
  // Slot 0 of k0 now observes point 12 (k0 did not see it): point 0 loses k0.
  ASSERT_TRUE(f.data.AddObservation(f.keyframes[0], 0, f.points[12]));
  EXPECT_EQ(f.data.FindMapPoint(f.points[0])->NumObservations(), 1);
  EXPECT_EQ(f.data.FindMapPoint(f.points[12])->observations.at(f.keyframes[0]), 0);
  // Point 12 seen by another keypoint of k0: the old slot is cleared.
  ASSERT_TRUE(f.data.AddObservation(f.keyframes[0], 19, f.points[12]));
  EXPECT_FALSE(f.data.FindKeyframe(f.keyframes[0])->map_point_ids[0].IsValid());
  EXPECT_EQ(f.data.FindMapPoint(f.points[12])->observations.at(f.keyframes[0]), 19);
  // k0 shares points 1..9 with k1 and now 12 too: 10; with k2 points 5..9 and 12: 6.
  EXPECT_EQ(f.data.covisibility().Weight(f.keyframes[0], f.keyframes[1]), 10);
  EXPECT_EQ(f.data.covisibility().Weight(f.keyframes[0], f.keyframes[2]), 6);
  EXPECT_EQ(f.data.CheckInvariants(), "");
}

TEST(MapDataTest, EraseMapPointAndObservation) {
  Fixture f;
  f.data.EraseObservation(f.keyframes[2], f.points[5]);
  EXPECT_EQ(f.data.covisibility().Weight(f.keyframes[0], f.keyframes[2]), 4);
  f.data.EraseMapPoint(f.points[6]);
  EXPECT_EQ(f.data.FindMapPoint(f.points[6]), nullptr);
  EXPECT_EQ(f.data.covisibility().Weight(f.keyframes[0], f.keyframes[2]), 3);
  EXPECT_EQ(f.data.covisibility().Weight(f.keyframes[1], f.keyframes[2]), 8);
  EXPECT_FALSE(f.data.FindKeyframe(f.keyframes[1])->map_point_ids[6].IsValid());
  EXPECT_EQ(f.data.NumMapPoints(), 14u);
  EXPECT_EQ(f.data.CheckInvariants(), "");
}

TEST(MapDataTest, EraseKeyframeRemovesItsObservationsAndOrphanPoints) {
  Fixture f;
  // Point 15 seen only by k2: erased with it.
  const MapPointId lonely = AddPoint(f.data, Eigen::Vector3d(0, 0, 3));
  ASSERT_TRUE(f.data.AddObservation(f.keyframes[2], 15, lonely));
  EXPECT_FALSE(f.data.EraseKeyframe(f.keyframes[0]));  // the first keyframe stays
  ASSERT_TRUE(f.data.EraseKeyframe(f.keyframes[2]));
  EXPECT_EQ(f.data.FindKeyframe(f.keyframes[2]), nullptr);
  EXPECT_EQ(f.data.FindMapPoint(lonely), nullptr);
  EXPECT_EQ(f.data.FindMapPoint(f.points[12])->NumObservations(), 1);
  EXPECT_EQ(f.data.covisibility().Neighbours(f.keyframes[1]).size(), 1u);
  EXPECT_EQ(f.data.LastKeyframe(), f.keyframes[1]);
  EXPECT_EQ(f.data.CheckInvariants(), "");
}

TEST(MapDataTest, AddKeyframeTakesItsMatchesAndStrongestParent) {
  Fixture f;
  Keyframe keyframe = MakeKeyframe(20, Eigen::Vector3d(3, 0, 0), 9);
  for (int j = 0; j < 4; ++j) keyframe.map_point_ids[j] = f.points[j];    // shared with k0, k1
  for (int j = 10; j < 15; ++j) keyframe.map_point_ids[j] = f.points[j];  // with k1, k2
  keyframe.map_point_ids[16] = f.points[0];        // a second keypoint for point 0: dropped
  keyframe.map_point_ids[17] = MapPointId(12345);  // unknown: dropped
  const KeyframeId id = f.data.AddKeyframe(std::move(keyframe));
  const Keyframe* stored = f.data.FindKeyframe(id);
  EXPECT_EQ(stored->NumMapPoints(), 9);
  EXPECT_FALSE(stored->map_point_ids[16].IsValid());
  EXPECT_FALSE(stored->map_point_ids[17].IsValid());
  EXPECT_EQ(f.data.covisibility().Weight(id, f.keyframes[1]), 9);
  EXPECT_EQ(f.data.covisibility().Weight(id, f.keyframes[0]), 4);
  EXPECT_EQ(f.data.covisibility().Weight(id, f.keyframes[2]), 5);
  EXPECT_EQ(f.data.covisibility().Parent(id), f.keyframes[1]);
  EXPECT_EQ(f.data.covisibility().BestCovisible(id, 2),
            (std::vector<KeyframeId>{f.keyframes[1], f.keyframes[2]}));
  EXPECT_EQ(f.data.CheckInvariants(), "");
}

TEST(MapDataTest, ReplaceMapPointMergesObservationsAndCounters) {
  Fixture f;
  // Point 20 duplicates point 2: seen by k2 (which does not see point 2) and by k1 at the
  // keypoint that sees point 17... use free slots 18 and 19.
  const MapPointId duplicate = AddPoint(f.data, Eigen::Vector3d(2, 1, 5));
  ASSERT_TRUE(f.data.AddObservation(f.keyframes[2], 18, duplicate));
  ASSERT_TRUE(f.data.AddObservation(f.keyframes[1], 19, duplicate));
  f.data.IncreaseVisible(duplicate, 4);
  f.data.IncreaseFound(duplicate, 2);
  f.data.ReplaceMapPoint(duplicate, f.points[2]);
  EXPECT_EQ(f.data.FindMapPoint(duplicate), nullptr);
  const MapPoint* kept = f.data.FindMapPoint(f.points[2]);
  EXPECT_EQ(kept->NumObservations(), 3);  // k0, k1 (its own slot 2), k2 (slot 18)
  EXPECT_EQ(kept->observations.at(f.keyframes[1]), 2);
  EXPECT_EQ(kept->observations.at(f.keyframes[2]), 18);
  EXPECT_FALSE(f.data.FindKeyframe(f.keyframes[1])->map_point_ids[19].IsValid());
  EXPECT_EQ(kept->num_visible, 1 + 5);
  EXPECT_EQ(kept->num_found, 1 + 3);
  EXPECT_EQ(f.data.CheckInvariants(), "");
}

// Five descriptors: d0 = 0, d1 = byte 0 set, d2 = byte 1 set, d3 = bytes 2..7, d4 = bytes
// 8..15. Median distances to the others (self included): 8, 16, 16, 56, 72 -> d0.
std::vector<OrbDescriptor> FiveDescriptors() {
  std::vector<OrbDescriptor> descriptors(5);
  for (auto& d : descriptors) d.fill(0);
  descriptors[1][0] = 0xff;
  descriptors[2][1] = 0xff;
  for (int b = 2; b < 8; ++b) descriptors[3][b] = 0xff;
  for (int b = 8; b < 16; ++b) descriptors[4][b] = 0xff;
  return descriptors;
}

TEST(MapPointTest, MedianDescriptorIndex) {
  const std::vector<OrbDescriptor> descriptors = FiveDescriptors();
  // Order them so that the answer is not the first.
  const std::vector<const std::uint8_t*> rows = {descriptors[3].data(), descriptors[1].data(),
                                                 descriptors[4].data(), descriptors[0].data(),
                                                 descriptors[2].data()};
  EXPECT_EQ(MedianDescriptorIndex(rows), 3);
  EXPECT_EQ(MedianDescriptorIndex({descriptors[2].data()}), 0);
  EXPECT_EQ(MedianDescriptorIndex({}), -1);
}

TEST(MapDataTest, DescriptorIsTheMedianObservation) {
  const std::vector<OrbDescriptor> descriptors = FiveDescriptors();
  MapData data;
  const MapPointId point = AddPoint(data, Eigen::Vector3d(0, 0, 5));
  for (int k : {4, 2, 0, 3, 1}) {
    Keyframe keyframe = MakeKeyframe(3, Eigen::Vector3d(k, 0, 0), k);
    std::copy(descriptors[k].begin(), descriptors[k].end(), keyframe.features.descriptors.ptr(1));
    keyframe.map_point_ids[1] = point;
    data.AddKeyframe(std::move(keyframe));
  }
  data.UpdateDescriptor(point);
  EXPECT_EQ(data.FindMapPoint(point)->descriptor, descriptors[0]);
  EXPECT_EQ(data.FindMapPoint(point)->NumObservations(), 5);
  EXPECT_EQ(data.CheckInvariants(), "");
}

TEST(MapDataTest, NormalAndDistanceRange) {
  Fixture f;
  // Point 7 at (7, 1, 5) seen from centres (0,0,0), (1,0,0), (2,0,0); reference k1.
  MapPoint point;
  point.p_in_world = Eigen::Vector3d(1, 0, 4);
  point.reference_keyframe = f.keyframes[1];
  const MapPointId id = f.data.AddMapPoint(point);
  ASSERT_TRUE(f.data.AddObservation(f.keyframes[0], 17, id));  // octave 17 % 3 = 2
  ASSERT_TRUE(f.data.AddObservation(f.keyframes[1], 16, id));  // octave 1
  ASSERT_TRUE(f.data.AddObservation(f.keyframes[2], 18, id));  // octave 0
  f.data.UpdateNormalAndDepth(id);
  const MapPoint* stored = f.data.FindMapPoint(id);
  const Eigen::Vector3d expected_normal =
      (Eigen::Vector3d(1, 0, 4).normalized() + Eigen::Vector3d(0, 0, 1) +
       Eigen::Vector3d(-1, 0, 4).normalized())
          .normalized();
  EXPECT_LT((stored->normal - expected_normal).norm(), 1e-12);
  // Reference k1 sees it at distance 4 on level 1: max = 4 * 1.2, min = max / 1.2^7.
  EXPECT_NEAR(stored->max_distance, 4.8, 1e-12);
  EXPECT_NEAR(stored->min_distance, 4.8 / std::pow(1.2, 7), 1e-12);
  const ScalePyramid pyramid = ScalePyramid::Make(8, 1.2);
  EXPECT_EQ(stored->PredictLevel(4.8, pyramid), 0);
  EXPECT_EQ(stored->PredictLevel(4.0, pyramid), 1);
  EXPECT_EQ(stored->PredictLevel(4.8 / std::pow(1.2, 3) + 1e-9, pyramid), 3);
  EXPECT_EQ(stored->PredictLevel(0.01, pyramid), 7);
}

}  // namespace
}  // namespace arucoslam
