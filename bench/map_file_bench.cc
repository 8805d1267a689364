// Save and load time of map files (io/map_file.h) for a map of 200 keyframes (1000 keypoints
// each) and 20000 points seen by 8 keyframes each: in memory, and through a file in /tmp.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <random>
#include <string>

#include "arucoslam/io/map_file.h"

namespace arucoslam {
namespace {

constexpr int kNumKeyframes = 200;
constexpr int kNumKeypoints = 1000;
constexpr int kNumPoints = 20000;
constexpr int kObservedPerKeyframe = 800;  // keypoints 0..799 observe points, the rest do not
constexpr int kPointStep = kNumPoints / kNumKeyframes;

Keyframe BenchKeyframe(int k, std::mt19937& random) {
  std::uniform_real_distribution<float> pixel(0.0f, 640.0f);
  Keyframe keyframe;
  keyframe.frame_id = FrameId(10 * k);
  keyframe.timestamp_s = 0.5 * k;
  keyframe.camera.width = 640;
  keyframe.camera.height = 480;
  keyframe.camera.fx = keyframe.camera.fy = 500.0;
  keyframe.camera.cx = 320.0;
  keyframe.camera.cy = 240.0;
  keyframe.cam_from_world =
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * k, Eigen::Vector3d::UnitY())),
             Eigen::Vector3d(-0.1 * k, 0.0, 0.0));
  OrbFeatures& features = keyframe.features;
  features.image_width = 640;
  features.image_height = 480;
  features.pyramid = ScalePyramid::Make(8, 1.2);
  features.descriptors = cv::Mat(kNumKeypoints, kOrbDescriptorBytes, CV_8U);
  cv::randu(features.descriptors, 0, 256);
  for (int i = 0; i < kNumKeypoints; ++i) {
    features.keypoints.emplace_back(pixel(random), pixel(random) * 0.75f, 31.0f,
                                    pixel(random) * 0.5f, 40.0f, i % 8);
    features.undistorted.emplace_back(features.keypoints.back().pt.x / 500.0 - 0.64,
                                      features.keypoints.back().pt.y / 500.0 - 0.48);
  }
  keyframe.map_point_ids.assign(kNumKeypoints, MapPointId());
  for (int i = 0; i < kObservedPerKeyframe; ++i) {
    keyframe.map_point_ids[i] = MapPointId((k * kPointStep + i) % kNumPoints);
  }
  return keyframe;
}

const MapData& BenchMap() {
  static const MapData* const map = [] {
    auto* data = new MapData();
    std::mt19937 random(42);
    std::uniform_real_distribution<double> uniform(-10.0, 10.0);
    for (int j = 0; j < kNumPoints; ++j) {
      MapPoint point;
      point.p_in_world = Eigen::Vector3d(uniform(random), uniform(random), 15.0);
      data->AddMapPoint(point);
    }
    for (int k = 0; k < kNumKeyframes; ++k) data->AddKeyframe(BenchKeyframe(k, random));
    for (const auto& [id, point] : std::map<MapPointId, MapPoint>(data->map_points())) {
      data->UpdateDescriptor(id);
      data->UpdateNormalAndDepth(id);
    }
    return data;
  }();
  return *map;
}

void SetCounters(benchmark::State& state, std::size_t bytes) {
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
  state.counters["file_MB"] = static_cast<double>(bytes) / 1e6;
}

void BM_SerializeMap(benchmark::State& state) {
  const MapData& map = BenchMap();
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::string file = SerializeMap(map);
    bytes = file.size();
    benchmark::DoNotOptimize(file.data());
  }
  SetCounters(state, bytes);
}
BENCHMARK(BM_SerializeMap)->Unit(benchmark::kMillisecond);

void BM_DeserializeMap(benchmark::State& state) {
  const std::string file = SerializeMap(BenchMap());
  for (auto _ : state) {
    MapData loaded = DeserializeMap(file, "bench.map");
    benchmark::DoNotOptimize(loaded.NumMapPoints());
  }
  SetCounters(state, file.size());
}
BENCHMARK(BM_DeserializeMap)->Unit(benchmark::kMillisecond);

void BM_SaveAndLoadMapFile(benchmark::State& state) {
  const MapData& map = BenchMap();
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "arucoslam_map_file_bench.map";
  for (auto _ : state) {
    SaveMapFile(map, path);
    MapData loaded = LoadMapFile(path);
    benchmark::DoNotOptimize(loaded.NumKeyframes());
  }
  SetCounters(state, std::filesystem::file_size(path));
  std::filesystem::remove(path);
}
BENCHMARK(BM_SaveAndLoadMapFile)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
