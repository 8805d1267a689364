#include "arucoslam/markers/detector_regions.h"

#include <gtest/gtest.h>

#include "arucoslam/markers/synthetic_view.h"

namespace arucoslam {
namespace {

const Eigen::Matrix3d kFacing = Eigen::Vector3d(1, -1, -1).asDiagonal();

// Markers 0-5 (0.2 m) at 1.5 to 4 m, spread over the view, slightly tilted.
std::vector<SyntheticMarker> SpreadMarkers() {
  std::vector<SyntheticMarker> markers;
  for (int i = 0; i < 6; ++i) {
    SyntheticMarker marker;
    marker.id = i;
    const double depth = 1.5 + 0.5 * i;
    const Eigen::Matrix3d tilt =
        Eigen::AngleAxisd(0.3 * (i % 3 - 1), Eigen::Vector3d::UnitY()).toRotationMatrix();
    marker.cam_from_marker = Rigid3(
        tilt * kFacing, Eigen::Vector3d(depth * (-0.45 + 0.18 * i), depth * 0.25 * (i % 2 ? 1 : -1), depth));
    markers.push_back(marker);
  }
  return markers;
}

// Regions around the true quads: every marker found with Detect's id and corners; markers
// outside the regions are not searched.
TEST(DetectInRegionsTest, SameAsDetectInsideRegions) {
  const MarkerDetector detector;
  const std::vector<SyntheticMarker> markers = SpreadMarkers();
  SyntheticViewOptions view;
  view.noise_sigma = 2.0;
  const cv::Mat image = RenderSyntheticView(SyntheticCamera640(), markers, view);
  const std::vector<MarkerDetection> whole = detector.Detect(image);
  ASSERT_EQ(whole.size(), markers.size());
  std::vector<PixelQuad> quads;
  for (int i = 0; i < 4; ++i) quads.push_back(ProjectMarkerQuads(
      [&] {
        MarkerMap map;
        MarkerInfo info;
        info.id = markers[i].id;
        info.size = markers[i].size;
        info.world_from_marker = markers[i].cam_from_marker;  // world = camera
        map.markers[info.id] = info;
        return map;
      }(),
      SyntheticCamera640(), Rigid3::Identity())[0]);
  const std::vector<cv::Rect> regions =
      SearchRegions(quads, image.size(), 0.2, MarkerRegionMargin(detector.options()));
  ASSERT_FALSE(regions.empty());
  EXPECT_LT(AreaFraction(regions, image.size()), 0.5);
  const std::vector<MarkerDetection> found = detector.DetectInRegions(image, regions);
  ASSERT_EQ(found.size(), 4u);
  for (std::size_t i = 0; i < found.size(); ++i) {
    EXPECT_EQ(found[i].id, whole[i].id);
    for (int k = 0; k < 4; ++k) {
      EXPECT_LT((found[i].corners[k] - whole[i].corners[k]).norm(), 1e-3) << i << " " << k;
    }
  }
}

// A region keeps the whole image's perimeter limits: a marker smaller than the minimum
// perimeter of the image (0.03 x 640 px) is not found in a small region either.
TEST(DetectInRegionsTest, KeepsTheWholeImagesPerimeterLimits) {
  DetectorOptions options;
  options.min_marker_perimeter_rate = 0.3;  // 192 px: a 40 px marker is too small
  const MarkerDetector detector(options);
  SyntheticMarker marker;
  marker.cam_from_marker = Rigid3(kFacing, Eigen::Vector3d(0.0, 0.0, 2.5));  // 40 px side
  const cv::Mat image = RenderSyntheticView(SyntheticCamera640(), {marker});
  ASSERT_TRUE(detector.Detect(image).empty());
  EXPECT_TRUE(detector.DetectInRegions(image, {cv::Rect(260, 180, 120, 120)}).empty());
  const MarkerDetector loose;  // default 0.03: found in the same region
  EXPECT_EQ(loose.DetectInRegions(image, {cv::Rect(260, 180, 120, 120)}).size(), 1u);
}

TEST(SearchRegionsTest, GrowsMergesAndClips) {
  const cv::Size image(640, 480);
  const PixelQuad a = {Eigen::Vector2d(100, 100), {140, 100}, {140, 140}, {100, 140}};
  const PixelQuad b = {Eigen::Vector2d(150, 110), {170, 110}, {170, 130}, {150, 130}};
  const PixelQuad edge = {Eigen::Vector2d(620, 460), {660, 460}, {660, 500}, {620, 500}};
  const PixelQuad outside = {Eigen::Vector2d(900, 100), {940, 100}, {940, 140}, {900, 140}};
  const std::vector<cv::Rect> regions = SearchRegions({a, b, edge, outside}, image, 0.25, 10);
  ASSERT_EQ(regions.size(), 2u);
  // a grown by 0.25 x 40 + 10 = 20 px: (80..160+1); b by 15: (135..185+1) -> merged.
  EXPECT_EQ(regions[0], cv::Rect(cv::Point(80, 80), cv::Point(186, 161)));
  EXPECT_EQ(regions[1], cv::Rect(cv::Point(600, 440), cv::Point(640, 480)));
  EXPECT_NEAR(AreaFraction(regions, image), (106.0 * 81 + 40 * 40) / (640.0 * 480), 1e-12);
}

TEST(ProjectMarkerQuadsTest, OnlyMarkersFacingTheCameraInFront) {
  MarkerMap map;
  const auto add = [&map](int id, const Rigid3& world_from_marker) {
    MarkerInfo info;
    info.id = id;
    info.size = 0.2;
    info.world_from_marker = world_from_marker;
    map.markers[id] = info;
  };
  add(0, Rigid3(kFacing, Eigen::Vector3d(0, 0, 2)));                          // seen
  add(1, Rigid3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.5, 0, 2)));     // back side
  add(2, Rigid3(kFacing, Eigen::Vector3d(0, 0, -2)));                          // behind
  const std::vector<PixelQuad> quads =
      ProjectMarkerQuads(map, SyntheticCamera640(), Rigid3::Identity());
  ASSERT_EQ(quads.size(), 1u);
  // 0.2 m at 2 m, f 500: 50 px side around the centre; top-left corner first.
  EXPECT_NEAR(quads[0][0].x(), 319.5 - 25.0, 1e-9);
  EXPECT_NEAR(quads[0][0].y(), 239.5 - 25.0, 1e-9);
  EXPECT_NEAR(quads[0][2].x(), 319.5 + 25.0, 1e-9);
}

// Whole image first, when the pose is unknown, and every full_scan_interval frames; regions
// around the projected markers in between, found as Detect finds them.
TEST(MarkerSearchPlannerTest, WholeImageOnScheduleRegionsInBetween) {
  const MarkerDetector detector;
  const std::vector<SyntheticMarker> markers = SpreadMarkers();
  MarkerMap map;  // world = camera
  for (const SyntheticMarker& marker : markers) {
    MarkerInfo info;
    info.id = marker.id;
    info.size = marker.size;
    info.world_from_marker = marker.cam_from_marker;
    map.markers[info.id] = info;
  }
  const cv::Mat image = RenderSyntheticView(SyntheticCamera640(), markers);
  const std::vector<MarkerDetection> whole = detector.Detect(image);
  ASSERT_EQ(whole.size(), markers.size());
  MarkerSearchOptions options;
  options.full_scan_interval = 3;
  options.pose_margin_px = 8.0;  // exact poses here; six markers would fill half the image
  MarkerSearchPlanner planner(SyntheticCamera640(), detector.options(), options);
  std::vector<bool> full;
  for (int frame = 0; frame < 7; ++frame) {
    const std::optional<std::vector<cv::Rect>> regions = planner.Next(map);
    full.push_back(!regions);
    if (regions) {
      EXPECT_LT(AreaFraction(*regions, image.size()), 0.5);
      const std::vector<MarkerDetection> found = detector.DetectInRegions(image, *regions);
      ASSERT_EQ(found.size(), whole.size());
      for (std::size_t i = 0; i < found.size(); ++i) EXPECT_EQ(found[i].id, whole[i].id);
    }
    // The pose is lost after frame 4: the next frame searches the whole image.
    planner.Remember(frame == 4 ? std::nullopt : std::optional<Rigid3>(Rigid3::Identity()),
                     whole);
  }
  EXPECT_EQ(full, std::vector<bool>({true, false, false, true, false, true, false}));
  EXPECT_EQ(planner.num_full_scans(), 3);
}

}  // namespace
}  // namespace arucoslam
