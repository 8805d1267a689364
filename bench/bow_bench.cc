// Bag-of-words benchmarks: loading the shipped vocabulary, turning one frame's 1000 ORB
// descriptors into a BoW vector (+ direct index), and querying a database of 500 keyframes.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "arucoslam/feature/orb_extractor.h"
#include "arucoslam/feature/place_database.h"
#include "arucoslam/feature/vocabulary.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

const fs::path kVocabulary =
    fs::path(ARUCOSLAM_SOURCE_DIR) / "data" / "vocabulary" / "orb_k10_l5.bin";
const fs::path kEuroc =
    fs::path(ARUCOSLAM_TEST_DATA_DIR) / "euroc_v101_micro" / "mav0" / "cam0" / "data";

const Vocabulary& ShippedVocabulary() {
  static const Vocabulary vocabulary = Vocabulary::Load(kVocabulary);
  return vocabulary;
}

// ORB descriptors (1000 per frame) of real frames when the EuRoC clip is there, else of
// random textures.
const std::vector<cv::Mat>& FrameDescriptors() {
  static const std::vector<cv::Mat> frames = [] {
    std::vector<cv::Mat> out;
    const OrbExtractor extractor(OrbExtractorOptions{});
    std::vector<fs::path> files;
    if (fs::is_directory(kEuroc)) {
      for (const auto& entry : fs::directory_iterator(kEuroc)) files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    for (std::size_t i = 0; i < files.size(); i += 5) {
      out.push_back(extractor.Extract(cv::imread(files[i].string(), cv::IMREAD_GRAYSCALE))
                        .descriptors);
    }
    cv::RNG rng(1);
    while (out.size() < 10) {
      cv::Mat image(480, 752, CV_8U);
      rng.fill(image, cv::RNG::UNIFORM, 0, 255);
      out.push_back(extractor.Extract(image).descriptors);
    }
    return out;
  }();
  return frames;
}

void BM_VocabularyLoad(benchmark::State& state) {
  if (!fs::is_regular_file(kVocabulary)) {
    state.SkipWithError(("missing " + kVocabulary.string()).c_str());
    return;
  }
  for (auto _ : state) benchmark::DoNotOptimize(Vocabulary::Load(kVocabulary));
  state.counters["words"] = static_cast<double>(ShippedVocabulary().num_words());
  state.counters["MB"] = static_cast<double>(fs::file_size(kVocabulary)) / 1e6;
}
BENCHMARK(BM_VocabularyLoad)->Unit(benchmark::kMillisecond);

void BM_TransformFrame(benchmark::State& state) {
  if (!fs::is_regular_file(kVocabulary)) {
    state.SkipWithError(("missing " + kVocabulary.string()).c_str());
    return;
  }
  const Vocabulary& vocabulary = ShippedVocabulary();
  const auto& frames = FrameDescriptors();
  std::size_t i = 0;
  BowVector bow;
  FeatureVector direct;
  for (auto _ : state) {
    vocabulary.Transform(frames[i++ % frames.size()], 2, &bow, &direct);
    benchmark::DoNotOptimize(bow);
  }
  state.counters["features"] = frames[0].rows;
}
BENCHMARK(BM_TransformFrame)->Unit(benchmark::kMicrosecond);

void BM_DatabaseQuery500(benchmark::State& state) {
  if (!fs::is_regular_file(kVocabulary)) {
    state.SkipWithError(("missing " + kVocabulary.string()).c_str());
    return;
  }
  const Vocabulary& vocabulary = ShippedVocabulary();
  const auto& frames = FrameDescriptors();
  // 500 keyframes: the frames with random halves of their features, so entries differ.
  PlaceDatabase database(vocabulary.num_words());
  std::mt19937_64 rng(2);
  std::vector<BowVector> queries;
  for (std::uint64_t id = 0; id < 500; ++id) {
    const cv::Mat& frame = frames[id % frames.size()];
    cv::Mat half;
    for (int r = 0; r < frame.rows; ++r) {
      if (rng() % 2 == 0) half.push_back(frame.row(r));
    }
    database.Add(id, vocabulary.Transform(half));
  }
  for (const cv::Mat& frame : frames) queries.push_back(vocabulary.Transform(frame));
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(database.Query(queries[i++ % queries.size()]));
  }
  state.counters["entries"] = static_cast<double>(database.size());
}
BENCHMARK(BM_DatabaseQuery500)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace arucoslam

BENCHMARK_MAIN();
