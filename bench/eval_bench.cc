// Speed of the evaluation on evo's test data: reading, time association, Umeyama alignment,
// APE and RPE (fr2/desk: 20957 ground-truth poses, 2893 estimated).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "arucoslam/eval/alignment.h"
#include "arucoslam/eval/association.h"
#include "arucoslam/eval/evaluation.h"
#include "arucoslam/eval/pose_error.h"
#include "arucoslam/io/trajectory_io.h"

namespace arucoslam {
namespace {

const std::filesystem::path kEvoData =
    std::filesystem::path(ARUCOSLAM_TEST_DATA_DIR) / "evo_testdata";

bool HaveData(benchmark::State& state) {
  if (std::filesystem::is_directory(kEvoData)) return true;
  state.SkipWithError(("missing test data folder " + kEvoData.string()).c_str());
  return false;
}

void BM_ReadTumGroundTruth(benchmark::State& state) {
  if (!HaveData(state)) return;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ReadTrajectory(kEvoData / "fr2_desk_groundtruth.txt"));
  }
}
BENCHMARK(BM_ReadTumGroundTruth)->Unit(benchmark::kMillisecond);

void BM_AssociateByTime(benchmark::State& state) {
  if (!HaveData(state)) return;
  const Trajectory gt = ReadTrajectory(kEvoData / "fr2_desk_groundtruth.txt");
  const Trajectory est = ReadTrajectory(kEvoData / "fr2_desk_ORB.txt");
  for (auto _ : state) benchmark::DoNotOptimize(AssociateByTime(gt, est, {}));
}
BENCHMARK(BM_AssociateByTime)->Unit(benchmark::kMicrosecond);

void BM_EvaluateSim3(benchmark::State& state) {
  if (!HaveData(state)) return;
  const Trajectory gt = ReadTrajectory(kEvoData / "fr2_desk_groundtruth.txt");
  const Trajectory est = ReadTrajectory(kEvoData / "fr2_desk_ORB.txt");
  EvaluationOptions options;
  options.alignment.mode = AlignmentMode::kSim3;
  for (auto _ : state) {
    benchmark::DoNotOptimize(EvaluateTrajectory(gt, est, "orb", "fr2_desk_ORB.txt", options));
  }
}
BENCHMARK(BM_EvaluateSim3)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
