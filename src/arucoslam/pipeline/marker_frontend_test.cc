// MarkerFrontend on a rendered view of a known marker and an unknown one: the whole image is
// searched until a frame has a pose in the marker world, then only around the markers expected
// from it; the frame's detections become its markers and locate it.
#include "arucoslam/pipeline/marker_frontend.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "arucoslam/markers/synthetic_view.h"

namespace arucoslam {
namespace {

constexpr int kKnownId = 3;
constexpr int kUnknownId = 7;

// Both markers face the camera 1.5 m ahead, the known one on the left, the unknown on the
// right. The world is the camera frame.
std::vector<SyntheticMarker> Markers() {
  const Eigen::Matrix3d facing = Eigen::Vector3d(1, -1, -1).asDiagonal();
  SyntheticMarker known;
  known.id = kKnownId;
  known.cam_from_marker = Rigid3(facing, Eigen::Vector3d(-0.4, 0.0, 1.5));
  SyntheticMarker unknown = known;
  unknown.id = kUnknownId;
  unknown.cam_from_marker = Rigid3(facing, Eigen::Vector3d(0.4, 0.0, 1.5));
  return {known, unknown};
}

// The known marker, or both (`with_unknown`).
MarkerMap KnownMap(bool with_unknown = false) {
  MarkerMap map;
  for (const SyntheticMarker& marker : Markers()) {
    if (marker.id == kUnknownId && !with_unknown) continue;
    MarkerInfo info;
    info.id = marker.id;
    info.size = marker.size;
    info.world_from_marker = marker.cam_from_marker;
    map.markers[info.id] = info;
  }
  return map;
}

std::vector<int> Ids(const std::vector<MarkerDetection>& detections) {
  std::vector<int> ids;
  for (const MarkerDetection& detection : detections) ids.push_back(detection.id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::vector<MarkerDetection> Detect(MarkerFrontend& frontend, const cv::Mat& image) {
  frontend.StartDetection(image, KnownMap());
  return frontend.WaitForDetections();
}

TEST(MarkerFrontendTest, SearchesAroundExpectedMarkersOnlyAfterAFramePosedInTheWorld) {
  const CameraModel camera = SyntheticCamera640();
  const cv::Mat image = RenderSyntheticView(camera, Markers());
  MarkerFrontend frontend(camera, DetectorOptions{}, MarkerSearchOptions{});
  const std::vector<MarkerDetection> all = Detect(frontend, image);
  EXPECT_EQ(Ids(all), (std::vector<int>{kKnownId, kUnknownId}));
  EXPECT_EQ(frontend.stats().num_full_scans, 1);
  const std::vector<MarkerDetection> known_only = {
      *std::find_if(all.begin(), all.end(), [](const auto& d) { return d.id == kKnownId; })};

  // A keypoint pose outside the marker world, no marker location: the whole image again.
  FrameReport unaligned;
  unaligned.cam_from_world = Rigid3();
  frontend.RememberFrame(unaligned, std::nullopt, known_only);
  EXPECT_EQ(Ids(Detect(frontend, image)).size(), 2u);
  EXPECT_EQ(frontend.stats().num_full_scans, 2);

  // A marker pose: only around the known marker, so the unknown one is not searched.
  FrameReport marker_pose = unaligned;
  marker_pose.marker_pose = true;
  frontend.RememberFrame(marker_pose, std::nullopt, known_only);
  EXPECT_EQ(Ids(Detect(frontend, image)), (std::vector<int>{kKnownId}));
  EXPECT_EQ(frontend.stats().num_full_scans, 2);

  // The same from the frame's marker location when its keypoint pose is outside the world.
  MarkerFix fix;
  fix.world_from_cam = Rigid3();
  frontend.RememberFrame(unaligned, fix, known_only);
  EXPECT_EQ(Ids(Detect(frontend, image)), (std::vector<int>{kKnownId}));
  EXPECT_EQ(frontend.stats().num_full_scans, 2);
}

TEST(MarkerFrontendTest, LocatesTheFrameFromItsDetections) {
  const CameraModel camera = SyntheticCamera640();
  const cv::Mat image = RenderSyntheticView(camera, Markers());
  MarkerFrontend frontend(camera, DetectorOptions{}, MarkerSearchOptions{});
  const MarkerMap both = KnownMap(/*with_unknown=*/true);
  MarkerFusion fusion(MarkerFusionOptions{}, camera, both, 0.2);
  const std::vector<MarkerDetection> detections = Detect(frontend, image);
  Frame frame;
  frame.camera = camera;
  frame.timestamp_s = 1.0;
  frontend.Locate(detections, both, MapPrediction{}, 0, &frame, &fusion);
  ASSERT_EQ(frame.markers.size(), 2u);
  ASSERT_TRUE(fusion.fix().has_value());
  EXPECT_LT(fusion.fix()->world_from_cam.translation.norm(), 0.02);  // the camera at the origin
  EXPECT_EQ(fusion.num_markers(), 2);
  const MarkerFrontendStats stats = frontend.stats();
  EXPECT_EQ(stats.marker_ms.Count(), 1u);
  EXPECT_EQ(stats.wait_ms.Count(), 1u);
}

TEST(MarkerFrontendTest, AnAbandonedDetectionLeavesTheWorkerFree) {
  const CameraModel camera = SyntheticCamera640();
  const cv::Mat image = RenderSyntheticView(camera, Markers());
  MarkerFrontend frontend(camera, DetectorOptions{}, MarkerSearchOptions{});
  frontend.StartDetection(image, KnownMap());
  frontend.AbandonDetection();
  EXPECT_EQ(Detect(frontend, image).size(), 2u);
}

}  // namespace
}  // namespace arucoslam
