#include "arucoslam/feature/bow_vector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

namespace arucoslam {
namespace {

// 1 - 0.5 |a - b|_1 computed on dense maps, the definition.
double DenseScore(const BowVector& a, const BowVector& b) {
  std::map<WordId, double> difference;
  for (const auto& e : a.entries) difference[e.word] += e.weight;
  for (const auto& e : b.entries) difference[e.word] -= e.weight;
  double l1 = 0.0;
  for (const auto& [word, value] : difference) l1 += std::abs(value);
  return 1.0 - 0.5 * l1;
}

BowVector RandomBow(std::mt19937_64& rng, int words, int max_word) {
  std::vector<std::pair<WordId, double>> pairs;
  for (int i = 0; i < words; ++i) {
    pairs.emplace_back(static_cast<WordId>(rng() % max_word), 0.01 + (rng() % 1000) / 1000.0);
  }
  BowVector bow = BowVector::FromPairs(pairs);
  bow.Normalize();
  return bow;
}

TEST(BowVector, FromPairsSumsSortsAndDropsNonPositive) {
  const BowVector bow = BowVector::FromPairs({{5, 0.5}, {2, 1.0}, {5, 0.25}, {3, 0.0}});
  ASSERT_EQ(bow.size(), 2u);
  EXPECT_EQ(bow.entries[0], (BowVector::Entry{2, 1.0}));
  EXPECT_EQ(bow.entries[1], (BowVector::Entry{5, 0.75}));
  BowVector normalised = bow;
  normalised.Normalize();
  EXPECT_DOUBLE_EQ(normalised.entries[0].weight, 1.0 / 1.75);
  EXPECT_DOUBLE_EQ(normalised.L1Norm(), 1.0);
}

TEST(BowVector, L1ScoreMatchesTheDefinition) {
  std::mt19937_64 rng(4);
  for (int trial = 0; trial < 50; ++trial) {
    const BowVector a = RandomBow(rng, 30, 60);
    const BowVector b = RandomBow(rng, 30, 60);
    EXPECT_NEAR(L1Score(a, b), DenseScore(a, b), 1e-12);
    EXPECT_NEAR(L1Score(a, b), L1Score(b, a), 1e-15);
    EXPECT_NEAR(L1Score(a, a), 1.0, 1e-12);
  }
  // Hand example: a = (0.5, 0.5, 0), b = (0, 0.5, 0.5): |a - b|_1 = 1 -> score 0.5.
  BowVector a = BowVector::FromPairs({{0, 0.5}, {1, 0.5}});
  BowVector b = BowVector::FromPairs({{1, 0.5}, {2, 0.5}});
  EXPECT_DOUBLE_EQ(L1Score(a, b), 0.5);
  EXPECT_EQ(L1Score(a, BowVector::FromPairs({{7, 1.0}})), 0.0);
  EXPECT_EQ(L1Score(a, BowVector{}), 0.0);
}

TEST(FeatureVector, GroupsAndCandidatePairs) {
  const FeatureVector a = FeatureVector::FromNodes({4, 2, 4, -1, 9});
  ASSERT_EQ(a.groups.size(), 3u);
  EXPECT_EQ(a.groups[0], (FeatureVector::Group{2, {1}}));
  EXPECT_EQ(a.groups[1], (FeatureVector::Group{4, {0, 2}}));
  EXPECT_EQ(a.groups[2], (FeatureVector::Group{9, {4}}));
  ASSERT_NE(a.Find(4), nullptr);
  EXPECT_EQ(a.Find(5), nullptr);
  const FeatureVector b = FeatureVector::FromNodes({4, 7, 9, 9});
  EXPECT_EQ(CandidatePairs(a, b),
            (std::vector<std::pair<int, int>>{{0, 0}, {2, 0}, {4, 2}, {4, 3}}));
}

}  // namespace
}  // namespace arucoslam
