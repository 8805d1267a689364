#include "arucoslam/feature/binary_kmeans.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <set>

namespace arucoslam {
namespace {

BinaryDescriptor RandomDescriptor(std::mt19937_64& rng) {
  BinaryDescriptor d;
  for (auto& byte : d) byte = static_cast<std::uint8_t>(rng() & 0xff);
  return d;
}

// `d` with `count` distinct bits flipped.
BinaryDescriptor FlipBits(BinaryDescriptor d, int count, std::mt19937_64& rng) {
  std::set<int> bits;
  while (static_cast<int>(bits.size()) < count) bits.insert(static_cast<int>(rng() % 256));
  for (int bit : bits) d[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
  return d;
}

int SummedDistance(const std::vector<BinaryDescriptor>& set, const BinaryDescriptor& center) {
  int sum = 0;
  for (const auto& d : set) sum += DescriptorDistance(d.data(), center.data());
  return sum;
}

TEST(BinaryKMeans, DescriptorDistanceCountsBits) {
  BinaryDescriptor a{};
  BinaryDescriptor b{};
  EXPECT_EQ(DescriptorDistance(a.data(), b.data()), 0);
  b[0] = 0xff;
  b[31] = 0x81;
  EXPECT_EQ(DescriptorDistance(a.data(), b.data()), 10);
  b.fill(0xff);
  EXPECT_EQ(DescriptorDistance(a.data(), b.data()), 256);
  std::mt19937_64 rng(2);
  for (int i = 0; i < 1000; ++i) {
    const std::uint64_t word = rng() >> (i % 64);
    EXPECT_EQ(CountBits(word), std::popcount(word)) << word;
  }
}

TEST(BinaryKMeans, MajorityIsTheBitwiseVoteAndMinimisesTheSummedDistance) {
  std::mt19937_64 rng(7);
  std::vector<BinaryDescriptor> set;
  for (int i = 0; i < 7; ++i) set.push_back(RandomDescriptor(rng));
  std::vector<std::uint32_t> all(set.size());
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  const BinaryDescriptor majority = MajorityDescriptor(set, all);
  for (int bit = 0; bit < 256; ++bit) {
    int ones = 0;
    for (const auto& d : set) ones += (d[bit / 8] >> (bit % 8)) & 1;
    EXPECT_EQ((majority[bit / 8] >> (bit % 8)) & 1, ones >= 4 ? 1 : 0) << "bit " << bit;
  }
  // No single-bit change lowers the summed Hamming distance (the majority is optimal bitwise).
  const int best = SummedDistance(set, majority);
  for (int bit = 0; bit < 256; ++bit) {
    BinaryDescriptor changed = majority;
    changed[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    EXPECT_GT(SummedDistance(set, changed), best) << "bit " << bit;  // odd count: strict
  }
}

TEST(BinaryKMeans, MajorityTieGivesZeroAndSelectionIsRespected) {
  std::vector<BinaryDescriptor> set(3);
  set[0].fill(0xff);
  set[1].fill(0x00);
  set[2].fill(0xff);
  EXPECT_EQ(MajorityDescriptor(set, {0, 1}), BinaryDescriptor{});  // 1 of 2: tie -> 0
  BinaryDescriptor ones;
  ones.fill(0xff);
  EXPECT_EQ(MajorityDescriptor(set, {0, 1, 2}), ones);
  EXPECT_EQ(MajorityDescriptor(set, {}), BinaryDescriptor{});
}

TEST(BinaryKMeans, RecoversPlantedClustersExactly) {
  std::mt19937_64 rng(11);
  const int num_clusters = 5;
  const int per_cluster = 40;
  std::vector<BinaryDescriptor> centers;
  std::vector<BinaryDescriptor> descriptors;
  std::vector<int> truth;
  for (int c = 0; c < num_clusters; ++c) centers.push_back(RandomDescriptor(rng));
  for (int i = 0; i < per_cluster; ++i) {
    for (int c = 0; c < num_clusters; ++c) {  // interleaved, so order says nothing
      descriptors.push_back(FlipBits(centers[c], 12, rng));
      truth.push_back(c);
    }
  }
  std::vector<std::uint32_t> all(descriptors.size());
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  std::mt19937_64 seed_rng(3);
  const KMajorityResult result = KMajority(descriptors, all, {num_clusters, 10}, seed_rng);
  ASSERT_EQ(result.centers.size(), static_cast<std::size_t>(num_clusters));
  std::set<int> found;
  for (std::size_t c = 0; c < result.centers.size(); ++c) {
    ASSERT_EQ(result.members[c].size(), static_cast<std::size_t>(per_cluster));
    const int planted = truth[result.members[c].front()];
    for (std::uint32_t m : result.members[c]) EXPECT_EQ(truth[m], planted);
    // 40 copies with 12 of 256 bits flipped each: the vote restores the planted centre.
    EXPECT_EQ(result.centers[c], centers[planted]);
    found.insert(planted);
  }
  EXPECT_EQ(found.size(), static_cast<std::size_t>(num_clusters));
}

TEST(BinaryKMeans, SameSeedSameResultAndFewDistinctDescriptors) {
  std::mt19937_64 rng(5);
  std::vector<BinaryDescriptor> descriptors;
  for (int i = 0; i < 300; ++i) descriptors.push_back(RandomDescriptor(rng));
  std::vector<std::uint32_t> all(descriptors.size());
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  std::mt19937_64 a(9);
  std::mt19937_64 b(9);
  const KMajorityResult first = KMajority(descriptors, all, {8, 5}, a);
  const KMajorityResult second = KMajority(descriptors, all, {8, 5}, b);
  EXPECT_EQ(first.centers, second.centers);
  EXPECT_EQ(first.members, second.members);

  // Three distinct values repeated: three clusters, whatever k.
  std::vector<BinaryDescriptor> repeated;
  for (int i = 0; i < 30; ++i) repeated.push_back(descriptors[i % 3]);
  std::vector<std::uint32_t> selection(repeated.size());
  for (std::uint32_t i = 0; i < selection.size(); ++i) selection[i] = i;
  const KMajorityResult few = KMajority(repeated, selection, {10, 5}, a);
  ASSERT_EQ(few.centers.size(), 3u);
  for (const auto& members : few.members) EXPECT_EQ(members.size(), 10u);
}

}  // namespace
}  // namespace arucoslam
