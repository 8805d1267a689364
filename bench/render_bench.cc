// Rendering throughput of the simulator at 640x480 on the default factory world along its
// default route: render only, render + PNG encoding, and the whole dataset writer.
#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <memory>
#include <unistd.h>

#include "arucoslam/sim/dataset_writer.h"
#include "arucoslam/sim/default_camera.h"
#include "arucoslam/sim/factory_world.h"
#include "arucoslam/sim/path.h"
#include "arucoslam/sim/renderer.h"
#include "arucoslam/sim/world_model.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

// The default factory written once to a temporary folder, with its repeat-run poses.
struct BenchWorld {
  fs::path dir;
  WorldModel world;
  std::vector<TimedPose> poses;

  BenchWorld() {
    dir = fs::temp_directory_path() / ("arucoslam_render_bench_" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const FactoryWorld factory = BuildFactoryWorld(FactoryOptions{});
    WriteFactoryWorld(factory, dir);
    world = LoadWorldModel(dir / "world.sdf");
    poses = GenerateCameraPath(factory.default_route, PathRun::kRepeat);
  }
  ~BenchWorld() { fs::remove_all(dir); }

  // Iteration i of a frame benchmark renders view i mod kViews: kViews poses evenly spread
  // over the route, so that every run (with its fixed iteration count) sees the same views.
  static constexpr std::size_t kViews = 32;
  const Rigid3& View(std::size_t i) const {
    return poses[(i % kViews) * (poses.size() / kViews)].world_from_cam;
  }
};

// Two passes over the views: the same work in every run, comparable between options.
constexpr int kFrameIterations = 2 * BenchWorld::kViews;

BenchWorld& World() {
  static BenchWorld world;
  return world;
}

// state.range(0): MSAA samples (llvmpipe offers 4 or none: 2 becomes 4).
void BM_RenderFrame(benchmark::State& state) {
  BenchWorld& bench = World();
  RenderOptions options;
  options.msaa_samples = static_cast<int>(state.range(0));
  options.noise_sigma = 2.0;
  Renderer renderer(bench.world, DefaultSimulatorCamera(), options);
  std::size_t i = 0;
  for (auto _ : state) {
    const RenderedFrame frame = renderer.Render(bench.View(i), i);
    benchmark::DoNotOptimize(frame.grey.data);
    ++i;
  }
  state.counters["frames/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
// CPU time is the whole process's (llvmpipe rasterises on its own threads), so it stays
// meaningful when the machine is loaded; wall time (frames/s) depends on the load.
BENCHMARK(BM_RenderFrame)
    ->Arg(1)
    ->Arg(4)
    ->Iterations(kFrameIterations)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// state.range(0): MSAA samples.
void BM_RenderAndEncodePng(benchmark::State& state) {
  BenchWorld& bench = World();
  RenderOptions options;
  options.msaa_samples = static_cast<int>(state.range(0));
  options.noise_sigma = 2.0;
  Renderer renderer(bench.world, DefaultSimulatorCamera(), options);
  std::size_t i = 0;
  std::vector<uchar> png;
  for (auto _ : state) {
    const RenderedFrame frame = renderer.Render(bench.View(i), i);
    cv::imencode(".png", frame.grey, png, {cv::IMWRITE_PNG_COMPRESSION, 1});
    benchmark::DoNotOptimize(png.data());
    ++i;
  }
  state.counters["frames/s"] = benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderAndEncodePng)
    ->Arg(1)
    ->Arg(4)
    ->Iterations(kFrameIterations)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// The whole writer (rendering overlapped with PNG writing) on the first 3 s of the route,
// world loading and OpenGL set-up included; state.range(0): MSAA samples.
void BM_WriteSequence(benchmark::State& state) {
  BenchWorld& bench = World();
  std::vector<TimedPose> poses(bench.poses.begin(),
                               bench.poses.begin() + std::min<std::size_t>(90, bench.poses.size()));
  DatasetWriterOptions options;
  options.render.noise_sigma = 2.0;
  options.render.msaa_samples = static_cast<int>(state.range(0));
  options.progress = false;
  for (auto _ : state) {
    WriteSimulatedSequence(bench.dir / "world.sdf", DefaultSimulatorCamera(), poses, bench.dir / "seq",
                           options);
  }
  state.counters["frames/s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * poses.size()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_WriteSequence)
    ->Arg(1)
    ->Arg(4)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Iterations(2);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
