// K-majority clustering of 256-bit binary descriptors (k-means with Hamming distance and the
// bitwise majority as centroid, k-means++ seeding): the building step of the Vocabulary tree.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "arucoslam/feature/keypoints.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

using BinaryDescriptor = std::array<std::uint8_t, kOrbDescriptorBytes>;

// Set bits of a 64-bit word, branch-free (the portable build has no popcnt instruction, and
// std::popcount would call a library routine).
inline int CountBits(std::uint64_t x) {
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return static_cast<int>((x * 0x0101010101010101ull) >> 56);
}

// Bits that differ between two 32-byte descriptors (0..256).
inline int DescriptorDistance(const std::uint8_t* a, const std::uint8_t* b) {
  int bits = 0;
  for (int k = 0; k < kOrbDescriptorBytes; k += 8) {
    std::uint64_t wa;
    std::uint64_t wb;
    std::memcpy(&wa, a + k, 8);
    std::memcpy(&wb, b + k, 8);
    bits += CountBits(wa ^ wb);
  }
  return bits;
}

// Bitwise majority of the selected descriptors: bit j is set when more than half of them
// have it set (a tie gives 0). Minimises the summed Hamming distance to them. All zeros for
// an empty selection.
BinaryDescriptor MajorityDescriptor(const std::vector<BinaryDescriptor>& descriptors,
                                    const std::vector<std::uint32_t>& selection);

struct KMajorityOptions {
  int k = 10;               // clusters wanted (fewer when there are fewer distinct descriptors)
  int max_iterations = 10;  // assignment/update rounds after seeding; stops earlier when stable
  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("k", k, 2);
    check.AtLeast("max_iterations", max_iterations, 1);
    return check.ok();
  }
};

struct KMajorityResult {
  std::vector<BinaryDescriptor> centers;            // no empty cluster
  std::vector<std::vector<std::uint32_t>> members;  // members[c]: entries of `selection`
};

// Clusters descriptors[selection[i]]. Seeding picks the first centre uniformly and each
// further one with probability proportional to the squared distance to the nearest chosen
// centre; `rng` makes it reproducible. With at most k distinct descriptors each distinct
// one becomes a cluster.
KMajorityResult KMajority(const std::vector<BinaryDescriptor>& descriptors,
                          const std::vector<std::uint32_t>& selection,
                          const KMajorityOptions& options, std::mt19937_64& rng);

}  // namespace arucoslam
