#include "arucoslam/map/marker_landmark.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arucoslam {
namespace {

MarkerInfo MakeInfo(int id, double size, bool fixed) {
  MarkerInfo info;
  info.id = id;
  info.size = size;
  info.fixed = fixed;
  info.world_from_marker =
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX())),
             Eigen::Vector3d(4.0, 1.5, 0.8));
  return info;
}

std::array<Eigen::Vector2d, 4> Corners(double offset) {
  return {Eigen::Vector2d(offset, 0), Eigen::Vector2d(offset + 10, 0),
          Eigen::Vector2d(offset + 10, 10), Eigen::Vector2d(offset, 10)};
}

TEST(MarkerLandmarkTest, CornersInWorldFollowPoseAndSize) {
  const MarkerLandmark landmark = MarkerLandmark::FromMarkerInfo(MakeInfo(7, 0.3, true));
  const auto corners = landmark.CornersInWorld();
  // Top-left corner (-0.15, 0.15, 0) rotated 90 degrees about x: (-0.15, 0, 0.15).
  EXPECT_NEAR((corners[0] - Eigen::Vector3d(3.85, 1.5, 0.95)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((corners[0] - corners[1]).norm(), 0.3, 1e-12);
  EXPECT_NEAR((corners[0] - corners[2]).norm(), 0.3 * std::sqrt(2.0), 1e-12);
}

TEST(MarkerLandmarksTest, AddRejectsDuplicatesInvalidIdsAndBadSizes) {
  MarkerLandmarks landmarks;
  EXPECT_TRUE(landmarks.Add(MarkerLandmark::FromMarkerInfo(MakeInfo(3, 0.2, true))));
  EXPECT_FALSE(landmarks.Add(MarkerLandmark::FromMarkerInfo(MakeInfo(3, 0.2, false))));
  EXPECT_FALSE(landmarks.Add(MarkerLandmark::FromMarkerInfo(MakeInfo(4, 0.0, false))));
  MarkerLandmark invalid;
  invalid.size = 0.2;
  EXPECT_FALSE(landmarks.Add(invalid));
  EXPECT_EQ(landmarks.size(), 1u);
  EXPECT_TRUE(landmarks.Find(MarkerId(3))->fixed);
}

TEST(MarkerLandmarksTest, ObservationsAreKeyedByKeyframeAndErasedWithIt) {
  MarkerLandmarks landmarks;
  landmarks.Add(MarkerLandmark::FromMarkerInfo(MakeInfo(1, 0.2, true)));
  landmarks.Add(MarkerLandmark::FromMarkerInfo(MakeInfo(2, 0.2, false)));
  EXPECT_TRUE(landmarks.AddObservation(MarkerId(1), KeyframeId(10), Corners(0)));
  EXPECT_TRUE(landmarks.AddObservation(MarkerId(1), KeyframeId(10), Corners(5)));  // replaces
  EXPECT_TRUE(landmarks.AddObservation(MarkerId(2), KeyframeId(10), Corners(1)));
  EXPECT_TRUE(landmarks.AddObservation(MarkerId(2), KeyframeId(11), Corners(2)));
  EXPECT_FALSE(landmarks.AddObservation(MarkerId(9), KeyframeId(10), Corners(0)));
  EXPECT_FALSE(landmarks.AddObservation(MarkerId(1), KeyframeId(), Corners(0)));
  ASSERT_EQ(landmarks.Find(MarkerId(1))->observations.size(), 1u);
  EXPECT_EQ(landmarks.Find(MarkerId(1))->observations.at(KeyframeId(10))[0].x(), 5.0);
  EXPECT_EQ(landmarks.EraseKeyframe(KeyframeId(10)), 2);
  EXPECT_TRUE(landmarks.Find(MarkerId(1))->observations.empty());
  EXPECT_EQ(landmarks.Find(MarkerId(2))->observations.size(), 1u);
  EXPECT_EQ(landmarks.EraseKeyframe(KeyframeId(10)), 0);
}

TEST(MarkerLandmarksTest, FixedMarkersKeepTheirPose) {
  MarkerLandmarks landmarks;
  landmarks.Add(MarkerLandmark::FromMarkerInfo(MakeInfo(1, 0.2, true)));
  landmarks.Add(MarkerLandmark::FromMarkerInfo(MakeInfo(2, 0.2, false)));
  const Rigid3 moved(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 2, 3));
  EXPECT_FALSE(landmarks.SetPose(MarkerId(1), moved));
  EXPECT_TRUE(landmarks.SetPose(MarkerId(2), moved));
  EXPECT_FALSE(landmarks.SetPose(MarkerId(5), moved));
  EXPECT_EQ(landmarks.Find(MarkerId(1))->world_from_marker.translation,
            Eigen::Vector3d(4.0, 1.5, 0.8));
  EXPECT_EQ(landmarks.Find(MarkerId(2))->world_from_marker.translation, Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(landmarks.Erase(MarkerId(2)));
  EXPECT_FALSE(landmarks.Erase(MarkerId(2)));
}

TEST(MarkerLandmarksTest, MarkerMapRoundTripKeepsPosesSizesAndFlags) {
  MarkerMap map;
  map.dictionary = "DICT_6X6_250";
  map.markers[5] = MakeInfo(5, 0.25, true);
  map.markers[8] = MakeInfo(8, 0.15, false);
  const MarkerLandmarks landmarks = MarkerLandmarks::FromMarkerMap(map);
  ASSERT_EQ(landmarks.size(), 2u);
  const MarkerMap back = landmarks.ToMarkerMap("DICT_6X6_250");
  EXPECT_EQ(back.dictionary, "DICT_6X6_250");
  ASSERT_EQ(back.markers.size(), 2u);
  for (const auto& [id, info] : map.markers) {
    const MarkerInfo& other = back.markers.at(id);
    EXPECT_EQ(other.id, id);
    EXPECT_EQ(other.size, info.size);
    EXPECT_EQ(other.fixed, info.fixed);
    EXPECT_EQ(other.world_from_marker.translation, info.world_from_marker.translation);
    EXPECT_NEAR(other.world_from_marker.rotation.angularDistance(info.world_from_marker.rotation),
                0.0, 1e-12);
  }
}

}  // namespace
}  // namespace arucoslam
