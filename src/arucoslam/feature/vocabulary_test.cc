#include "arucoslam/feature/vocabulary.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

BinaryDescriptor RandomDescriptor(std::mt19937_64& rng) {
  BinaryDescriptor d;
  for (auto& byte : d) byte = static_cast<std::uint8_t>(rng() & 0xff);
  return d;
}

BinaryDescriptor FlipBits(BinaryDescriptor d, int count, std::mt19937_64& rng) {
  std::set<int> bits;
  while (static_cast<int>(bits.size()) < count) bits.insert(static_cast<int>(rng() % 256));
  for (int bit : bits) d[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
  return d;
}

cv::Mat ToMat(const std::vector<BinaryDescriptor>& descriptors) {
  cv::Mat mat(static_cast<int>(descriptors.size()), kOrbDescriptorBytes, CV_8U);
  for (int r = 0; r < mat.rows; ++r) {
    std::memcpy(mat.ptr<std::uint8_t>(r), descriptors[r].data(), kOrbDescriptorBytes);
  }
  return mat;
}

// A planted two-level hierarchy: 3 far-apart top centres, each with 3 sub-centres 40 bits
// away, each with noisy copies 4 bits away. Group g = 3 * top + sub is one word.
struct PlantedWorld {
  static constexpr int kGroups = 9;
  std::vector<BinaryDescriptor> sub_centers;
  // Noisy copies of group g's sub-centre.
  std::vector<BinaryDescriptor> Sample(int group, int count, std::mt19937_64& rng) const {
    std::vector<BinaryDescriptor> out;
    for (int i = 0; i < count; ++i) out.push_back(FlipBits(sub_centers[group], 4, rng));
    return out;
  }
};

PlantedWorld MakePlantedWorld(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  PlantedWorld world;
  for (int top = 0; top < 3; ++top) {
    const BinaryDescriptor center = RandomDescriptor(rng);
    for (int sub = 0; sub < 3; ++sub) world.sub_centers.push_back(FlipBits(center, 40, rng));
  }
  return world;
}

// Training images: image i holds 8 samples of each group g with (i + g) % 3 != 0 for g < 6,
// and groups 6..8 appear in every image; so groups 0..5 are in 2/3 of the images.
std::vector<cv::Mat> TrainingImages(const PlantedWorld& world, int num_images) {
  std::mt19937_64 rng(99);
  std::vector<cv::Mat> images;
  for (int i = 0; i < num_images; ++i) {
    std::vector<BinaryDescriptor> image;
    for (int g = 0; g < PlantedWorld::kGroups; ++g) {
      if (g < 6 && (i + g) % 3 == 0) continue;
      for (const auto& d : world.Sample(g, 8, rng)) image.push_back(d);
    }
    images.push_back(ToMat(image));
  }
  return images;
}

class VocabularyTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new PlantedWorld(MakePlantedWorld(1));
    VocabularyOptions options;
    options.branching = 3;
    options.levels = 2;
    vocabulary_ = new Vocabulary(Vocabulary::Train(TrainingImages(*world_, 12), options));
  }
  static void TearDownTestSuite() {
    delete vocabulary_;
    delete world_;
  }
  static PlantedWorld* world_;
  static Vocabulary* vocabulary_;
};
PlantedWorld* VocabularyTest::world_ = nullptr;
Vocabulary* VocabularyTest::vocabulary_ = nullptr;

TEST_F(VocabularyTest, TreeHasThePlantedShape) {
  EXPECT_EQ(vocabulary_->branching(), 3);
  EXPECT_EQ(vocabulary_->levels(), 2);
  EXPECT_EQ(vocabulary_->num_nodes(), 1u + 3u + 9u);
  EXPECT_EQ(vocabulary_->num_words(), 9u);
  EXPECT_EQ(vocabulary_->num_training_images(), 12u);
  for (WordId w = 0; w < vocabulary_->num_words(); ++w) {
    EXPECT_EQ(vocabulary_->node(vocabulary_->WordNode(w)).depth, 2u);
  }
}

TEST_F(VocabularyTest, FreshDescriptorsReachTheLeafOfTheirGroup) {
  std::mt19937_64 rng(1234);  // samples never seen in training
  std::set<WordId> words;
  for (int g = 0; g < PlantedWorld::kGroups; ++g) {
    const WordId leaf = vocabulary_->Transform(world_->sub_centers[g].data());
    words.insert(leaf);
    // The leaf's centre is the planted sub-centre (restored by the majority vote).
    EXPECT_EQ(vocabulary_->node(vocabulary_->WordNode(leaf)).descriptor, world_->sub_centers[g]);
    for (const auto& d : world_->Sample(g, 20, rng)) {
      NodeId top = 0;
      EXPECT_EQ(vocabulary_->Transform(d.data(), &top, 1), leaf) << "group " << g;
      // The depth-1 node is the leaf's parent.
      EXPECT_EQ(top, vocabulary_->node(vocabulary_->WordNode(leaf)).parent);
    }
  }
  EXPECT_EQ(words.size(), 9u);  // one word per group
}

TEST_F(VocabularyTest, IdfWeightsFollowTheTrainingImages) {
  for (int g = 0; g < PlantedWorld::kGroups; ++g) {
    const WordId w = vocabulary_->Transform(world_->sub_centers[g].data());
    // Groups 0..5 appear in 8 of 12 images, groups 6..8 in all of them.
    const double expected = g < 6 ? std::log(12.0 / 8.0) : 0.0;
    EXPECT_NEAR(vocabulary_->WordWeight(w), expected, 1e-12) << "group " << g;
  }
}

TEST_F(VocabularyTest, BowVectorIsTfIdfAndL1Normalised) {
  std::mt19937_64 rng(5);
  std::vector<BinaryDescriptor> image = world_->Sample(0, 3, rng);
  for (const auto& d : world_->Sample(1, 1, rng)) image.push_back(d);
  for (const auto& d : world_->Sample(7, 5, rng)) image.push_back(d);  // idf 0: dropped
  const BowVector bow = vocabulary_->Transform(ToMat(image));
  ASSERT_EQ(bow.size(), 2u);
  EXPECT_NEAR(bow.L1Norm(), 1.0, 1e-12);
  const WordId w0 = vocabulary_->Transform(world_->sub_centers[0].data());
  for (const auto& entry : bow.entries) {
    EXPECT_NEAR(entry.weight, entry.word == w0 ? 0.75 : 0.25, 1e-12);  // 3 : 1 occurrences
  }
}

TEST_F(VocabularyTest, ScoresAreOneForTheSameImageAndZeroForDisjointOnes) {
  std::mt19937_64 rng(8);
  std::vector<BinaryDescriptor> a = world_->Sample(0, 10, rng);
  for (const auto& d : world_->Sample(3, 10, rng)) a.push_back(d);
  std::vector<BinaryDescriptor> b = world_->Sample(1, 10, rng);
  for (const auto& d : world_->Sample(4, 10, rng)) b.push_back(d);
  const BowVector bow_a = vocabulary_->Transform(ToMat(a));
  const BowVector bow_b = vocabulary_->Transform(ToMat(b));
  EXPECT_NEAR(L1Score(bow_a, bow_a), 1.0, 1e-12);
  EXPECT_EQ(L1Score(bow_a, bow_b), 0.0);
  // Another view of the same groups (fresh noise) scores 1 too; a half overlap 0.5.
  std::vector<BinaryDescriptor> a2 = world_->Sample(0, 10, rng);
  for (const auto& d : world_->Sample(3, 10, rng)) a2.push_back(d);
  EXPECT_NEAR(L1Score(bow_a, vocabulary_->Transform(ToMat(a2))), 1.0, 1e-12);
  std::vector<BinaryDescriptor> half = world_->Sample(0, 10, rng);
  for (const auto& d : world_->Sample(4, 10, rng)) half.push_back(d);
  EXPECT_NEAR(L1Score(bow_a, vocabulary_->Transform(ToMat(half))), 0.5, 1e-12);
}

TEST_F(VocabularyTest, DirectIndexGroupsFeaturesByNode) {
  std::mt19937_64 rng(21);
  std::vector<BinaryDescriptor> image = world_->Sample(0, 2, rng);     // top 0
  for (const auto& d : world_->Sample(1, 2, rng)) image.push_back(d);  // top 0
  for (const auto& d : world_->Sample(4, 3, rng)) image.push_back(d);  // top 1
  BowVector bow;
  FeatureVector direct;
  vocabulary_->Transform(ToMat(image), 1, &bow, &direct);
  ASSERT_EQ(direct.groups.size(), 2u);
  std::vector<std::vector<int>> groups;
  for (const auto& group : direct.groups) {
    EXPECT_EQ(vocabulary_->node(group.node).depth, 1u);
    groups.push_back(group.features);
  }
  std::sort(groups.begin(), groups.end());
  EXPECT_EQ(groups[0], (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(groups[1], (std::vector<int>{4, 5, 6}));
  // At the leaves the two groups of top 0 separate.
  vocabulary_->Transform(ToMat(image), 2, &bow, &direct);
  EXPECT_EQ(direct.groups.size(), 3u);
}

TEST_F(VocabularyTest, TrainingIsDeterministic) {
  VocabularyOptions options;
  options.branching = 3;
  options.levels = 2;
  EXPECT_EQ(Vocabulary::Train(TrainingImages(*world_, 12), options), *vocabulary_);
}

TEST(Vocabulary, RejectsBadInput) {
  VocabularyOptions options;
  EXPECT_TRUE(options.Check());
  options.branching = 1;
  EXPECT_FALSE(options.Check());
  options = {};
  options.levels = 0;
  EXPECT_FALSE(options.Check());
  EXPECT_THROW(Vocabulary::Train({}, VocabularyOptions{}), std::invalid_argument);
  EXPECT_THROW(Vocabulary::Train({cv::Mat(3, 16, CV_8U)}, VocabularyOptions{}),
               std::invalid_argument);
  const Vocabulary empty;
  EXPECT_TRUE(empty.Transform(cv::Mat(2, 32, CV_8U, cv::Scalar(0))).empty());
}

}  // namespace
}  // namespace arucoslam
