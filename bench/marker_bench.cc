// Marker pipeline speed: detection per 640x480 and 1280x720 frame (rendered markers over a
// textured background), with the small-marker options, on a real AprilTag photo, IPPE pose
// per marker, and the camera locator per frame.
#include <benchmark/benchmark.h>

#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/marker_pose.h"
#include "arucoslam/markers/preprocess.h"
#include "arucoslam/markers/synthetic_view.h"

namespace arucoslam {
namespace {

CameraModel Camera(int width, int height) {
  CameraModel camera;
  camera.width = width;
  camera.height = height;
  camera.fx = camera.fy = 500.0 * width / 640.0;
  camera.cx = 0.5 * (width - 1);
  camera.cy = 0.5 * (height - 1);
  return camera;
}

// Four 0.2 m markers 1.5-3 m away, tilted, spread over the image.
std::vector<SyntheticMarker> Markers(const std::string& dictionary = "DICT_4X4_50") {
  std::vector<SyntheticMarker> markers;
  const Eigen::Matrix3d facing = Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.6, 0.8, 0)) *
                                 Eigen::Vector3d(1, -1, -1).asDiagonal();
  const Eigen::Vector3d positions[4] = {
      {-0.6, -0.3, 2.0}, {0.5, -0.3, 1.5}, {0.5, 0.4, 3.0}, {-0.5, 0.4, 2.5}};
  for (int i = 0; i < 4; ++i) {
    SyntheticMarker marker;
    marker.dictionary = dictionary;
    marker.id = 2 * i + 1;
    marker.cam_from_marker = Rigid3(facing, positions[i]);
    markers.push_back(marker);
  }
  return markers;
}

// The timed loop of the detection benchmarks: `detector` on `image`, the markers it finds
// as a counter.
void TimeDetection(benchmark::State& state, const MarkerDetector& detector,
                   const cv::Mat& image) {
  size_t found = 0;
  for (auto _ : state) {
    const std::vector<MarkerDetection> detections = detector.Detect(image);
    found = detections.size();
    benchmark::DoNotOptimize(detections.data());
  }
  state.counters["markers"] = static_cast<double>(found);
}

void BM_Detect(benchmark::State& state) {
  const CameraModel camera =
      Camera(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const cv::Mat image = RenderSyntheticView(camera, Markers(), {});
  const MarkerDetector detector;
  TimeDetection(state, detector, image);
}
BENCHMARK(BM_Detect)->Args({640, 480})->Args({1280, 720})->Unit(benchmark::kMillisecond);

// The default options with tag36h11 markers at 640x480, with the corners moved onto the
// AprilTag quad fit (1, the default for AprilTag dictionaries) or not (0).
void BM_DetectAprilTagDictionary(benchmark::State& state) {
  const std::string dictionary = "DICT_APRILTAG_36h11";
  const cv::Mat image = RenderSyntheticView(Camera(640, 480), Markers(dictionary), {});
  DetectorOptions options;
  options.dictionary = dictionary;
  options.april_tag_quad_corners = state.range(0) != 0;
  const MarkerDetector detector(options);
  TimeDetection(state, detector, image);
}
BENCHMARK(BM_DetectAprilTagDictionary)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The default options at 640x480 with the threshold line fit of the corners (1) or without.
void BM_DetectThresholdLineFit(benchmark::State& state) {
  const cv::Mat image = RenderSyntheticView(Camera(640, 480), Markers(), {});
  DetectorOptions options;
  options.threshold_line_fit = state.range(0) != 0;
  const MarkerDetector detector(options);
  TimeDetection(state, detector, image);
}
BENCHMARK(BM_DetectThresholdLineFit)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The default options at 640x480 with the edge refit of 20-60 px markers' corners (1, the
// default) or cornerSubPix's corners only (0).
void BM_DetectEdgeRefinement(benchmark::State& state) {
  const cv::Mat image = RenderSyntheticView(Camera(640, 480), Markers(), {});
  DetectorOptions options;
  options.edge_refinement = state.range(0) != 0;
  const MarkerDetector detector(options);
  TimeDetection(state, detector, image);
}
BENCHMARK(BM_DetectEdgeRefinement)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The small-marker options of DetectorOptions at 640x480: upsample factor x 10 (10: none)
// and the second decoding of rejected candidates (0 or 1).
void BM_DetectSmallMarkerOptions(benchmark::State& state) {
  const cv::Mat image = RenderSyntheticView(Camera(640, 480), Markers(), {});
  DetectorOptions options;
  options.upsample = 0.1 * static_cast<double>(state.range(0));
  options.rescue_rejected = state.range(1) != 0;
  const MarkerDetector detector(options);
  TimeDetection(state, detector, image);
}
BENCHMARK(BM_DetectSmallMarkerOptions)
    ->Args({10, 1})
    ->Args({20, 0})
    ->Args({20, 1})
    ->Args({30, 0})
    ->Unit(benchmark::kMillisecond);

// The real-photo options of the apriltag_detect_unit test (799x533 photo, tag36h11, AprilTag
// quads at 2x with the rescue decoder): with and without its contour candidates (first
// argument 1 or 0), the threshold line fit of the corners (second argument 1 or 0) and the
// corners moved onto the AprilTag quad fit at full resolution (third argument 1 or 0).
void BM_DetectAprilTagPhoto(benchmark::State& state) {
  const std::string path =
      std::string(ARUCOSLAM_TEST_DATA_DIR) + "/apriltag_detect_unit/34085369442_304b6bafd9_c.jpg";
  const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) {
    state.SkipWithError("apriltag_detect_unit photo missing");
    return;
  }
  DetectorOptions options;
  options.dictionary = "DICT_APRILTAG_36h11";
  options.corner_refinement = CornerRefinement::kAprilTag;
  options.perspective_remove_pixel_per_cell = 4;
  options.perspective_remove_ignored_margin_per_cell = 0.25;
  options.upsample = 2.0;
  options.rescue_rejected = true;
  options.rescue_contour_candidates = state.range(0) != 0;
  options.threshold_line_fit = state.range(1) != 0;
  options.april_tag_quad_corners = state.range(2) != 0;
  const MarkerDetector detector(options);
  TimeDetection(state, detector, image);
}
BENCHMARK(BM_DetectAprilTagPhoto)
    ->Args({0, 0, 0})
    ->Args({1, 0, 0})
    ->Args({1, 1, 0})
    ->Args({1, 0, 1})
    ->Unit(benchmark::kMillisecond);

void BM_PreprocessClahe(benchmark::State& state) {
  const CameraModel camera = Camera(640, 480);
  const cv::Mat image = RenderSyntheticView(camera, Markers(), {});
  PreprocessOptions options;
  options.clahe = true;
  for (auto _ : state) benchmark::DoNotOptimize(Preprocess(image, options).data);
}
BENCHMARK(BM_PreprocessClahe)->Unit(benchmark::kMillisecond);

void BM_MarkerPose(benchmark::State& state) {
  const CameraModel camera = Camera(640, 480);
  const std::vector<SyntheticMarker> markers = Markers();
  MarkerDetection detection;
  detection.id = markers[0].id;
  detection.corners = ProjectMarkerCorners(camera, markers[0]);
  for (auto _ : state) benchmark::DoNotOptimize(EstimateMarkerPose(detection, 0.2, camera));
}
BENCHMARK(BM_MarkerPose)->Unit(benchmark::kMicrosecond);

void BM_LocateCamera(benchmark::State& state) {
  const CameraModel camera = Camera(640, 480);
  const std::vector<SyntheticMarker> markers = Markers();
  MarkerMap map;
  std::vector<MarkerDetection> detections;
  for (int i = 0; i < state.range(0); ++i) {
    MarkerInfo info;
    info.id = markers[i].id;
    info.size = 0.2;
    info.world_from_marker = markers[i].cam_from_marker;  // world = camera frame
    map.markers[info.id] = info;
    MarkerDetection detection;
    detection.id = info.id;
    detection.corners = ProjectMarkerCorners(camera, markers[i]);
    detections.push_back(detection);
  }
  for (auto _ : state) benchmark::DoNotOptimize(LocateCamera(detections, map, camera).found);
}
BENCHMARK(BM_LocateCamera)->Arg(1)->Arg(4)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
