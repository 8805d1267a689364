// ORB extraction, matching and initialisation timings: our extractor vs cv::ORB (1000
// features, 8 levels, factor 1.2) on real EuRoC frames at 752x480 and a 640x480 crop and a
// KITTI frame at 1226x370, with the spread of the keypoints (fraction of the cells of an 8x6
// grid that hold one).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "arucoslam/feature/feature_grid.h"
#include "arucoslam/feature/orb_extractor.h"
#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/feature/undistort.h"
#include "arucoslam/slam/initializer.h"

namespace arucoslam {
namespace {

const std::string kEurocImages =
    std::string(ARUCOSLAM_TEST_DATA_DIR) + "/euroc_v101_micro/mav0/cam0/data";

// Frame `index` of the clip at 752x480, or cropped to its central 640x480.
cv::Mat LoadFrame(int index, int width) {
  std::vector<std::filesystem::path> files;
  if (std::filesystem::is_directory(kEurocImages)) {
    for (const auto& entry : std::filesystem::directory_iterator(kEurocImages)) {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  if (files.size() <= static_cast<std::size_t>(index)) return cv::Mat();
  const cv::Mat image = cv::imread(files[index].string(), cv::IMREAD_GRAYSCALE);
  if (width >= image.cols) return image;
  return image(cv::Rect((image.cols - width) / 2, 0, width, image.rows)).clone();
}

const std::string kKittiFrame =
    std::string(ARUCOSLAM_TEST_DATA_DIR) + "/kitti07_first160/original/image_0/000000.png";

// The EuRoC frame at width 640 or 752, the KITTI frame at 1226 (empty when missing).
cv::Mat LoadBenchFrame(int width) {
  if (width == 1226) return cv::imread(kKittiFrame, cv::IMREAD_GRAYSCALE);
  return LoadFrame(10, width);
}

double OccupiedFraction(const std::vector<cv::KeyPoint>& keypoints, cv::Size size) {
  std::vector<bool> occupied(48, false);
  for (const cv::KeyPoint& kp : keypoints) {
    const int cx = std::clamp(static_cast<int>(kp.pt.x * 8 / size.width), 0, 7);
    const int cy = std::clamp(static_cast<int>(kp.pt.y * 6 / size.height), 0, 5);
    occupied[cy * 8 + cx] = true;
  }
  return std::count(occupied.begin(), occupied.end(), true) / 48.0;
}

// Args: image width (640, 752: EuRoC; 1226: KITTI), OrbExtractorOptions::num_threads.
void BM_OwnOrbExtract(benchmark::State& state) {
  const cv::Mat image = LoadBenchFrame(static_cast<int>(state.range(0)));
  if (image.empty()) {
    state.SkipWithError("euroc_v101_micro or kitti07_first160 missing");
    return;
  }
  OrbExtractorOptions options;
  options.num_threads = static_cast<int>(state.range(1));
  const OrbExtractor extractor(options);
  OrbFeatures features;
  for (auto _ : state) {
    features = extractor.Extract(image);
    benchmark::DoNotOptimize(features.descriptors.data);
  }
  state.counters["keypoints"] = static_cast<double>(features.size());
  state.counters["occupied_8x6"] = OccupiedFraction(features.keypoints, image.size());
}
BENCHMARK(BM_OwnOrbExtract)
    ->ArgsProduct({{640, 752, 1226}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();

void BM_OpenCvOrbExtract(benchmark::State& state) {
  const cv::Mat image = LoadBenchFrame(static_cast<int>(state.range(0)));
  if (image.empty()) {
    state.SkipWithError("euroc_v101_micro missing");
    return;
  }
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(1000, 1.2f, 8);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  for (auto _ : state) {
    orb->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
    benchmark::DoNotOptimize(descriptors.data);
  }
  state.counters["keypoints"] = static_cast<double>(keypoints.size());
  state.counters["occupied_8x6"] = OccupiedFraction(keypoints, image.size());
}
BENCHMARK(BM_OpenCvOrbExtract)->Arg(640)->Arg(752)->Arg(1226)->Unit(benchmark::kMillisecond);

void BM_MatchBruteForce(benchmark::State& state) {
  const cv::Mat image1 = LoadFrame(10, 752), image2 = LoadFrame(30, 752);
  if (image1.empty() || image2.empty()) {
    state.SkipWithError("euroc_v101_micro missing");
    return;
  }
  const OrbExtractor extractor;
  const OrbFeatures features1 = extractor.Extract(image1), features2 = extractor.Extract(image2);
  std::size_t matches = 0;
  for (auto _ : state) matches = MatchBruteForce(features1, features2).size();
  state.counters["matches"] = static_cast<double>(matches);
}
BENCHMARK(BM_MatchBruteForce)->Unit(benchmark::kMillisecond);

void BM_MatchInWindow(benchmark::State& state) {
  const cv::Mat image1 = LoadFrame(10, 752), image2 = LoadFrame(30, 752);
  if (image1.empty() || image2.empty()) {
    state.SkipWithError("euroc_v101_micro missing");
    return;
  }
  const OrbExtractor extractor;
  const OrbFeatures features1 = extractor.Extract(image1), features2 = extractor.Extract(image2);
  std::vector<Eigen::Vector2d> predicted;
  for (const cv::KeyPoint& kp : features1.keypoints) predicted.emplace_back(kp.pt.x, kp.pt.y);
  std::size_t matches = 0;
  for (auto _ : state) {
    const FeatureGrid grid(features2);
    matches = MatchInWindow(features1, features2, grid, predicted).size();
  }
  state.counters["matches"] = static_cast<double>(matches);
}
BENCHMARK(BM_MatchInWindow)->Unit(benchmark::kMillisecond);

// cam0 of EuRoC V1_01 (euroc_v101_micro/README.md): radial-tangential, strong barrel.
CameraModel EurocCam0() {
  CameraModel camera;
  camera.width = 752;
  camera.height = 480;
  camera.fx = 458.654;
  camera.fy = 457.296;
  camera.cx = 367.215;
  camera.cy = 248.375;
  camera.model = DistortionModel::kRadTan;
  camera.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0};
  return camera;
}

// UndistortFeatures on the keypoints of a real frame (1000) with the EuRoC calibration.
void BM_UndistortFeatures(benchmark::State& state) {
  const cv::Mat image = LoadFrame(10, 752);
  if (image.empty()) {
    state.SkipWithError("euroc_v101_micro missing");
    return;
  }
  const CameraModel camera = EurocCam0();
  OrbFeatures features = OrbExtractor().Extract(image);
  for (auto _ : state) {
    UndistortFeatures(camera, &features);
    benchmark::DoNotOptimize(features.undistorted.data());
  }
  state.counters["keypoints"] = static_cast<double>(features.size());
}
BENCHMARK(BM_UndistortFeatures)->Unit(benchmark::kMicrosecond);

// One initialisation attempt on two real frames of the static clip (refused: the common
// case while a tracker waits for parallax), with the real calibration.
void BM_InitializeStaticPair(benchmark::State& state) {
  const cv::Mat image1 = LoadFrame(0, 752), image2 = LoadFrame(50, 752);
  if (image1.empty() || image2.empty()) {
    state.SkipWithError("euroc_v101_micro missing");
    return;
  }
  const CameraModel camera = EurocCam0();
  const OrbExtractor extractor;
  OrbFeatures features1 = extractor.Extract(image1), features2 = extractor.Extract(image2);
  UndistortFeatures(camera, &features1);
  UndistortFeatures(camera, &features2);
  InitializerOptions options;
  options.min_median_flow_px = static_cast<double>(state.range(0));
  options.min_translation_flow_px = static_cast<double>(state.range(0));
  const Initializer initializer(options);
  int matches = 0;
  for (auto _ : state) {
    const InitializationResult result = initializer.Initialize(features1, features2, camera);
    matches = result.num_matches;
    benchmark::DoNotOptimize(result.success);
  }
  state.counters["matches"] = matches;
}
// Arg: flow gates in pixels (2 = default, 0 = off: every model and motion test runs).
BENCHMARK(BM_InitializeStaticPair)->Arg(2)->Arg(0)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
