// The shipped vocabulary on real images it was not trained on: EuRoC frames (the same room
// seen twice) against outdoor AprilTag photos (unrelated scenes).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "arucoslam/feature/orb_extractor.h"
#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/feature/place_database.h"
#include "arucoslam/feature/vocabulary.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

const fs::path kVocabulary =
    fs::path(ARUCOSLAM_SOURCE_DIR) / "data" / "vocabulary" / "orb_k10_l5.bin";
const fs::path kData(ARUCOSLAM_TEST_DATA_DIR);
const fs::path kEuroc = kData / "euroc_v101_micro" / "mav0" / "cam0" / "data";
const fs::path kAprilTag = kData / "apriltag_detect_unit";

std::vector<fs::path> ImagesIn(const fs::path& folder, const std::string& extension) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() == extension) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

OrbFeatures Features(const fs::path& image) {
  static const OrbExtractor extractor(OrbExtractorOptions{});
  return extractor.Extract(cv::imread(image.string(), cv::IMREAD_GRAYSCALE));
}

class ShippedVocabularyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::is_regular_file(kVocabulary)) << "the shipped vocabulary is missing";
    if (!fs::is_directory(kEuroc) || !fs::is_directory(kAprilTag)) {
      GTEST_SKIP() << "test data missing: " << kEuroc << " or " << kAprilTag
                   << " (euroc_v101_micro, apriltag_detect_unit)";
    }
    if (vocabulary_ == nullptr) vocabulary_ = new Vocabulary(Vocabulary::Load(kVocabulary));
  }
  static Vocabulary* vocabulary_;
};
Vocabulary* ShippedVocabularyTest::vocabulary_ = nullptr;

TEST_F(ShippedVocabularyTest, SameSceneScoresHigherThanUnrelatedPhotos) {
  EXPECT_EQ(vocabulary_->branching(), 10);
  EXPECT_EQ(vocabulary_->levels(), 5);
  const std::vector<fs::path> euroc = ImagesIn(kEuroc, ".png");
  const std::vector<fs::path> photos = ImagesIn(kAprilTag, ".jpg");
  ASSERT_GE(euroc.size(), 90u);
  ASSERT_EQ(photos.size(), 3u);
  std::vector<BowVector> unrelated;
  for (const fs::path& photo : photos) {
    unrelated.push_back(vocabulary_->Transform(Features(photo).descriptors));
  }
  double worst_same = 1.0;
  double best_unrelated = 0.0;
  for (std::size_t i = 0; i + 30 < euroc.size(); i += 30) {
    const BowVector a = vocabulary_->Transform(Features(euroc[i]).descriptors);
    const BowVector b = vocabulary_->Transform(Features(euroc[i + 30]).descriptors);
    worst_same = std::min(worst_same, L1Score(a, b));
    for (const BowVector& u : unrelated) best_unrelated = std::max(best_unrelated, L1Score(a, u));
  }
  RecordProperty("worst_same_scene_score", std::to_string(worst_same));
  RecordProperty("best_unrelated_score", std::to_string(best_unrelated));
  std::printf("EuRoC frame pairs 1 s apart: worst score %.3f; vs AprilTag photos: best %.3f\n",
              worst_same, best_unrelated);
  EXPECT_GT(worst_same, 2.0 * best_unrelated);
}

TEST_F(ShippedVocabularyTest, DatabaseRanksTheSameRoomFirst) {
  const std::vector<fs::path> euroc = ImagesIn(kEuroc, ".png");
  PlaceDatabase database(vocabulary_->num_words());
  const std::vector<fs::path> photos = ImagesIn(kAprilTag, ".jpg");
  for (std::size_t i = 0; i < photos.size(); ++i) {
    database.Add(100 + i, vocabulary_->Transform(Features(photos[i]).descriptors));
  }
  database.Add(0, vocabulary_->Transform(Features(euroc[0]).descriptors));
  for (std::size_t i = 20; i < euroc.size(); i += 25) {
    const auto matches = database.Query(vocabulary_->Transform(Features(euroc[i]).descriptors));
    ASSERT_FALSE(matches.empty());
    EXPECT_EQ(matches[0].entry, 0u) << "frame " << i;
  }
}

// Fraction of `matches` whose pair shares a node at `depth` in both direct indexes, and the
// number of candidate pairs the direct index proposes.
std::pair<double, std::size_t> DirectIndexRecall(const Vocabulary& vocabulary,
                                                 const OrbFeatures& a, const OrbFeatures& b,
                                                 const std::vector<FeatureMatch>& matches,
                                                 int depth) {
  BowVector bow;
  FeatureVector direct_a;
  FeatureVector direct_b;
  vocabulary.Transform(a.descriptors, depth, &bow, &direct_a);
  vocabulary.Transform(b.descriptors, depth, &bow, &direct_b);
  std::set<std::pair<int, int>> candidates;
  for (const auto& pair : CandidatePairs(direct_a, direct_b)) candidates.insert(pair);
  int kept = 0;
  for (const FeatureMatch& m : matches) kept += candidates.count({m.index1, m.index2});
  std::printf("direct index at depth %d keeps %d of %zu matches (%.1f %%), %zu candidate pairs "
              "of %zu\n",
              depth, kept, matches.size(), 100.0 * kept / matches.size(), candidates.size(),
              a.size() * b.size());
  return {static_cast<double>(kept) / matches.size(), candidates.size()};
}

TEST_F(ShippedVocabularyTest, DirectIndexKeepsMostTrueMatches) {
  // Mutual brute-force matches between two frames of the same room, and how many of them
  // matching through the direct index would still find.
  const std::vector<fs::path> euroc = ImagesIn(kEuroc, ".png");
  const OrbFeatures a = Features(euroc[10]);
  const OrbFeatures b = Features(euroc[40]);
  BruteForceMatchOptions options;
  options.max_distance = 40;
  const std::vector<FeatureMatch> matches = MatchBruteForce(a, b, options);
  ASSERT_GT(matches.size(), 100u);
  const std::size_t all_pairs = a.size() * b.size();
  const auto [recall1, pairs1] = DirectIndexRecall(*vocabulary_, a, b, matches, 1);
  const auto [recall2, pairs2] = DirectIndexRecall(*vocabulary_, a, b, matches, 2);
  // Depth 1 (10 nodes): most matches kept at under a fifth of the comparisons.
  EXPECT_GT(recall1, 0.8);
  EXPECT_LT(pairs1, all_pairs / 5);
  // Depth 2 (100 nodes): a finer cut trades recall for far fewer comparisons.
  EXPECT_GE(recall1, recall2);
  EXPECT_LT(pairs2, all_pairs / 20);
}

}  // namespace
}  // namespace arucoslam
