#include "arucoslam/map/map.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace arucoslam {
namespace {

Keyframe MakeKeyframe(int num_keypoints) {
  Keyframe keyframe;
  keyframe.features.pyramid = ScalePyramid::Make(8, 1.2);
  keyframe.features.keypoints.assign(num_keypoints, cv::KeyPoint(1.0f, 1.0f, 31.0f));
  keyframe.features.descriptors = cv::Mat::zeros(num_keypoints, kOrbDescriptorBytes, CV_8U);
  keyframe.map_point_ids.assign(num_keypoints, MapPointId());
  return keyframe;
}

TEST(MapTest, ReadAndWriteReturnValues) {
  Map map;
  const KeyframeId id = map.Write([](MapData& data) { return data.AddKeyframe(MakeKeyframe(5)); });
  EXPECT_EQ(map.NumKeyframes(), 1u);
  EXPECT_EQ(map.Read([&](const MapData& data) { return data.FindKeyframe(id)->NumMapPoints(); }),
            0);
  const std::uint64_t version = map.Version();
  map.Read([](const MapData&) {});
  EXPECT_EQ(map.Version(), version);  // reads do not count
  map.Write([](MapData&) {});
  EXPECT_EQ(map.Version(), version + 1);
}

// Two writers (one adds keyframes observing shared points, one erases points) and a reader
// that checks the invariants while they run: the map must be consistent at every read.
TEST(MapTest, ConcurrentWritersKeepInvariants) {
  Map map;
  constexpr int kPoints = 200;
  std::vector<MapPointId> points = map.Write([&](MapData& data) {
    data.AddKeyframe(MakeKeyframe(kPoints));
    std::vector<MapPointId> ids;
    for (int j = 0; j < kPoints; ++j) ids.push_back(data.AddMapPoint(MapPoint{}));
    return ids;
  });
  std::atomic<bool> done{false};
  std::atomic<int> violations{0};
  std::thread adder([&] {
    for (int k = 0; k < 60; ++k) {
      map.Write([&](MapData& data) {
        const KeyframeId id = data.AddKeyframe(MakeKeyframe(kPoints));
        for (int j = k % 3; j < kPoints; j += 3) data.AddObservation(id, j, points[j]);
      });
    }
  });
  std::thread eraser([&] {
    for (int j = 0; j < kPoints; j += 4) {
      map.Write([&](MapData& data) { data.EraseMapPoint(points[j]); });
    }
  });
  std::thread reader([&] {
    while (!done) {
      if (!map.Read([](const MapData& data) { return data.CheckInvariants(); }).empty()) {
        ++violations;
      }
    }
  });
  adder.join();
  eraser.join();
  done = true;
  reader.join();
  EXPECT_EQ(violations.load(), 0);
  EXPECT_EQ(map.NumKeyframes(), 61u);
  EXPECT_EQ(map.NumMapPoints(), static_cast<std::size_t>(kPoints - kPoints / 4));
  EXPECT_EQ(map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

}  // namespace
}  // namespace arucoslam
