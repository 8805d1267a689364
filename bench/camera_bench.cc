// Throughput of the camera models: Project, Unproject (iterative) and ProjectJacobian for
// pinhole, radial-tangential (EuRoC cam0), equidistant fisheye (TUM-VI cam0), rational
// (PhotonVision's LifeCam) and tilted-sensor (the LifeCam with thin-prism terms and a tilt)
// cameras.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "arucoslam/geometry/camera.h"

namespace arucoslam {
namespace {

CameraModel BenchCamera(DistortionModel model) {
  CameraModel camera;
  if (model == DistortionModel::kRational || model == DistortionModel::kTilted) {
    camera.width = 1280;
    camera.height = 720;
    camera.fx = 1144.027;
    camera.fy = 1142.187;
    camera.cx = 604.858;
    camera.cy = 343.699;
    camera.distortion = {0.16443, -0.98662, 0.003473, -0.002772, 1.89095, 0.04109, 0.06374,
                         -0.06795};
    if (model == DistortionModel::kTilted) {
      for (int i = 8; i < 14; ++i) camera.distortion[i] = i < 12 ? 0.002 : 0.03;
    }
  } else if (model == DistortionModel::kEquidistant) {
    camera.width = 512;
    camera.height = 512;
    camera.fx = 190.978;
    camera.fy = 190.973;
    camera.cx = 254.932;
    camera.cy = 256.897;
    camera.distortion = {0.0034824, 0.00071503, -0.0020532, 0.00020294, 0.0};
  } else {
    camera.width = 752;
    camera.height = 480;
    camera.fx = 458.654;
    camera.fy = 457.296;
    camera.cx = 367.215;
    camera.cy = 248.375;
    if (model == DistortionModel::kRadTan) {
      camera.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0};
    }
  }
  camera.model = model;
  return camera;
}

constexpr int kNumSamples = 4096;

// Points in front of the camera that project inside the image.
std::vector<Eigen::Vector3d> PointsInView(const CameraModel& camera) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0.0, camera.width - 1.0), v(0.0, camera.height - 1.0);
  std::uniform_real_distribution<double> depth(0.5, 10.0);
  std::vector<Eigen::Vector3d> points;
  while (static_cast<int>(points.size()) < kNumSamples) {
    const Eigen::Vector2d pixel(u(rng), v(rng));
    // Fisheye: stay inside the image circle.
    if (camera.model == DistortionModel::kEquidistant &&
        (pixel - Eigen::Vector2d(camera.cx, camera.cy)).norm() > 250.0) {
      continue;
    }
    points.push_back(depth(rng) * camera.Unproject(pixel).homogeneous());
  }
  return points;
}

std::vector<Eigen::Vector2d> Pixels(const CameraModel& camera) {
  std::vector<Eigen::Vector2d> pixels;
  for (const auto& p : PointsInView(camera)) pixels.push_back(*camera.Project(p));
  return pixels;
}

void BM_Project(benchmark::State& state, DistortionModel model) {
  const CameraModel camera = BenchCamera(model);
  const auto points = PointsInView(camera);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(camera.Project(points[i]));
    i = (i + 1) % points.size();
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_Unproject(benchmark::State& state, DistortionModel model) {
  const CameraModel camera = BenchCamera(model);
  const auto pixels = Pixels(camera);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(camera.Unproject(pixels[i]));
    i = (i + 1) % pixels.size();
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_ProjectJacobian(benchmark::State& state, DistortionModel model) {
  const CameraModel camera = BenchCamera(model);
  const auto points = PointsInView(camera);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(camera.ProjectJacobian(points[i]));
    i = (i + 1) % points.size();
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK_CAPTURE(BM_Project, none, DistortionModel::kNone);
BENCHMARK_CAPTURE(BM_Project, radtan, DistortionModel::kRadTan);
BENCHMARK_CAPTURE(BM_Project, equidistant, DistortionModel::kEquidistant);
BENCHMARK_CAPTURE(BM_Unproject, none, DistortionModel::kNone);
BENCHMARK_CAPTURE(BM_Unproject, radtan, DistortionModel::kRadTan);
BENCHMARK_CAPTURE(BM_Unproject, equidistant, DistortionModel::kEquidistant);
BENCHMARK_CAPTURE(BM_ProjectJacobian, radtan, DistortionModel::kRadTan);
BENCHMARK_CAPTURE(BM_ProjectJacobian, equidistant, DistortionModel::kEquidistant);
BENCHMARK_CAPTURE(BM_Project, rational, DistortionModel::kRational);
BENCHMARK_CAPTURE(BM_Project, tilted, DistortionModel::kTilted);
BENCHMARK_CAPTURE(BM_Unproject, rational, DistortionModel::kRational);
BENCHMARK_CAPTURE(BM_Unproject, tilted, DistortionModel::kTilted);
BENCHMARK_CAPTURE(BM_ProjectJacobian, rational, DistortionModel::kRational);
BENCHMARK_CAPTURE(BM_ProjectJacobian, tilted, DistortionModel::kTilted);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
