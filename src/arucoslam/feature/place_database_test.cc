#include "arucoslam/feature/place_database.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "arucoslam/util/ids.h"

namespace arucoslam {
namespace {

BowVector RandomBow(std::mt19937_64& rng, int words, int max_word) {
  std::vector<std::pair<WordId, double>> pairs;
  for (int i = 0; i < words; ++i) {
    pairs.emplace_back(static_cast<WordId>(rng() % max_word), 0.01 + (rng() % 1000) / 1000.0);
  }
  BowVector bow = BowVector::FromPairs(pairs);
  bow.Normalize();
  return bow;
}

// `bow` with a fraction of its words replaced by random ones: a noisy second view.
BowVector Perturb(const BowVector& bow, double fraction, std::mt19937_64& rng, int max_word) {
  std::vector<std::pair<WordId, double>> pairs;
  for (const auto& e : bow.entries) {
    const bool replace = (rng() % 1000) < fraction * 1000;
    pairs.emplace_back(replace ? static_cast<WordId>(rng() % max_word) : e.word, e.weight);
  }
  BowVector out = BowVector::FromPairs(pairs);
  out.Normalize();
  return out;
}

TEST(PlaceDatabase, QueryScoresEqualL1ScoreAndRankTheTrueMatchFirst) {
  std::mt19937_64 rng(3);
  const int kWords = 5000;
  PlaceDatabase database(kWords);
  std::vector<BowVector> places;
  for (std::uint64_t id = 0; id < 200; ++id) {
    places.push_back(RandomBow(rng, 150, kWords));
    database.Add(id * 10, places.back());  // ids need not be dense
  }
  EXPECT_EQ(database.size(), 200u);
  for (int place = 0; place < 200; place += 7) {
    const BowVector query = Perturb(places[place], 0.4, rng, kWords);
    PlaceQueryOptions options;
    options.max_results = 5;
    const std::vector<PlaceMatch> matches = database.Query(query, options);
    ASSERT_EQ(matches.size(), 5u);
    EXPECT_EQ(matches[0].entry, static_cast<std::uint64_t>(place) * 10);
    for (std::size_t i = 0; i < matches.size(); ++i) {
      EXPECT_NEAR(matches[i].score, L1Score(query, places[matches[i].entry / 10]), 1e-12);
      if (i > 0) EXPECT_LE(matches[i].score, matches[i - 1].score);
    }
    // A 40 % perturbed view keeps most of the mass: far above unrelated places.
    EXPECT_GT(matches[0].score, 0.4);
    EXPECT_LT(matches[1].score, 0.15);
  }
}

TEST(PlaceDatabase, EraseReplaceFilterAndThresholds) {
  std::mt19937_64 rng(8);
  PlaceDatabase database;  // grows on demand
  const BowVector a = RandomBow(rng, 40, 300);
  const BowVector b = RandomBow(rng, 40, 300);
  database.Add(1, a);
  database.Add(2, b);
  database.Add(3, a);
  ASSERT_EQ(database.size(), 3u);
  std::vector<PlaceMatch> matches = database.Query(a);
  ASSERT_GE(matches.size(), 2u);
  EXPECT_EQ(matches[0].entry, 1u);  // tie with 3: lower id first
  EXPECT_EQ(matches[1].entry, 3u);
  EXPECT_NEAR(matches[0].score, 1.0, 1e-12);
  EXPECT_EQ(matches[0].num_shared_words, static_cast<int>(a.size()));

  // keep() filter and min_score.
  matches = database.Query(a, {}, [](std::uint64_t entry) { return entry != 1; });
  EXPECT_EQ(matches[0].entry, 3u);
  PlaceQueryOptions strict;
  strict.min_score = 0.99;
  matches = database.Query(a, strict);
  EXPECT_EQ(matches.size(), 2u);

  EXPECT_TRUE(database.Erase(3));
  EXPECT_FALSE(database.Erase(3));
  EXPECT_FALSE(database.Contains(3));
  for (const auto& e : a.entries) {
    for (const auto& posting : database.Postings(e.word)) EXPECT_NE(posting.entry, 3u);
  }
  // Replacing entry 1 by b: a query with a no longer finds a perfect match.
  database.Add(1, b);
  EXPECT_EQ(database.size(), 2u);
  matches = database.Query(a);
  for (const auto& m : matches) EXPECT_LT(m.score, 1.0 - 1e-9);
  EXPECT_NEAR(database.Query(b)[0].score, 1.0, 1e-12);
  database.Clear();
  EXPECT_TRUE(database.Query(b).empty());
  EXPECT_FALSE(PlaceQueryOptions{0}.Check());
}

TEST(PlaceDatabase, TypedIdsAndDirectIndexAreKept) {
  using PlaceId = StrongId<struct PlaceIdTag>;
  TypedPlaceDatabase<PlaceId> database(100);
  const BowVector bow = BowVector::FromPairs({{3, 0.5}, {9, 0.5}});
  database.Add(PlaceId(42), bow, FeatureVector::FromNodes({1, 1, 5}));
  const auto matches = database.Query(bow);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].id, PlaceId(42));
  EXPECT_EQ(matches[0].num_shared_words, 2);
  ASSERT_NE(database.Direct(PlaceId(42)), nullptr);
  EXPECT_EQ(database.Direct(PlaceId(42))->groups.size(), 2u);
  EXPECT_TRUE(database.Query(bow, {}, [](PlaceId id) { return id != PlaceId(42); }).empty());
  EXPECT_TRUE(database.Erase(PlaceId(42)));
  EXPECT_EQ(database.size(), 0u);
}

}  // namespace
}  // namespace arucoslam
