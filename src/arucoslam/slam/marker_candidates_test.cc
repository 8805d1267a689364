#include "arucoslam/slam/marker_candidates.h"

#include <gtest/gtest.h>

namespace arucoslam {
namespace {

MarkerObservation Seen(int id) { return {MarkerId(id), {}}; }

KeyframeId AddKeyframe(MapData& data, std::vector<MarkerObservation> markers) {
  Keyframe keyframe;
  keyframe.features.descriptors = cv::Mat::zeros(0, kOrbDescriptorBytes, CV_8U);
  keyframe.markers = std::move(markers);
  return data.AddKeyframe(std::move(keyframe));
}

TEST(MarkerCandidatesTest, MostSharedMarkersFirstThenMostRecent) {
  MapData data;
  const KeyframeId a = AddKeyframe(data, {Seen(1)});
  const KeyframeId b = AddKeyframe(data, {Seen(1), Seen(2)});
  AddKeyframe(data, {Seen(3)});
  const KeyframeId d = AddKeyframe(data, {Seen(2)});
  AddKeyframe(data, {});
  const std::vector<MarkerObservation> frame = {Seen(2), Seen(1), Seen(9)};
  EXPECT_EQ(KeyframesSeeingMarkers(data, frame, 10), (std::vector<KeyframeId>{b, d, a}));
  EXPECT_EQ(KeyframesSeeingMarkers(data, frame, 2), (std::vector<KeyframeId>{b, d}));
  EXPECT_TRUE(KeyframesSeeingMarkers(data, {Seen(9)}, 10).empty());
  EXPECT_TRUE(KeyframesSeeingMarkers(data, {}, 10).empty());
}

}  // namespace
}  // namespace arucoslam
