#include "arucoslam/feature/binary_kmeans.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace arucoslam {
namespace {

// Uniform double in [0, 1) from 53 random bits (same on every platform, unlike
// std::uniform_real_distribution).
double UniformUnit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Index of the nearest centre (lowest index on ties) and its distance.
std::pair<int, int> Nearest(const std::vector<BinaryDescriptor>& centers, const std::uint8_t* d) {
  int best = 0;
  int best_distance = std::numeric_limits<int>::max();
  for (std::size_t c = 0; c < centers.size(); ++c) {
    const int distance = DescriptorDistance(centers[c].data(), d);
    if (distance < best_distance) {
      best_distance = distance;
      best = static_cast<int>(c);
    }
  }
  return {best, best_distance};
}

// k-means++ seeding over the selected descriptors; stops early when every descriptor
// coincides with a chosen centre.
std::vector<BinaryDescriptor> SeedCenters(const std::vector<BinaryDescriptor>& descriptors,
                                          const std::vector<std::uint32_t>& selection, int k,
                                          std::mt19937_64& rng) {
  const std::size_t n = selection.size();
  std::vector<BinaryDescriptor> centers;
  centers.push_back(descriptors[selection[rng() % n]]);
  std::vector<double> squared(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double d = DescriptorDistance(centers[0].data(), descriptors[selection[i]].data());
    squared[i] = d * d;
  }
  while (static_cast<int>(centers.size()) < k) {
    double total = 0.0;
    for (double s : squared) total += s;
    if (total <= 0.0) break;  // fewer distinct descriptors than k
    const double target = UniformUnit(rng) * total;
    double cumulative = 0.0;
    std::size_t pick = n - 1;
    for (std::size_t i = 0; i < n; ++i) {
      cumulative += squared[i];
      if (cumulative > target && squared[i] > 0.0) {
        pick = i;
        break;
      }
    }
    while (squared[pick] <= 0.0) --pick;  // rounding at the end of the sum
    centers.push_back(descriptors[selection[pick]]);
    for (std::size_t i = 0; i < n; ++i) {
      const double d = DescriptorDistance(centers.back().data(), descriptors[selection[i]].data());
      squared[i] = std::min(squared[i], d * d);
    }
  }
  return centers;
}

}  // namespace

BinaryDescriptor MajorityDescriptor(const std::vector<BinaryDescriptor>& descriptors,
                                    const std::vector<std::uint32_t>& selection) {
  std::array<std::uint32_t, kOrbDescriptorBytes * 8> counts{};
  for (std::uint32_t index : selection) {
    const BinaryDescriptor& d = descriptors[index];
    for (int byte = 0; byte < kOrbDescriptorBytes; ++byte) {
      const unsigned value = d[byte];
      std::uint32_t* c = &counts[byte * 8];
      for (int bit = 0; bit < 8; ++bit) c[bit] += (value >> bit) & 1u;
    }
  }
  BinaryDescriptor majority{};
  for (int byte = 0; byte < kOrbDescriptorBytes; ++byte) {
    unsigned value = 0;
    for (int bit = 0; bit < 8; ++bit) {
      if (2 * static_cast<std::size_t>(counts[byte * 8 + bit]) > selection.size()) {
        value |= 1u << bit;
      }
    }
    majority[byte] = static_cast<std::uint8_t>(value);
  }
  return majority;
}

KMajorityResult KMajority(const std::vector<BinaryDescriptor>& descriptors,
                          const std::vector<std::uint32_t>& selection,
                          const KMajorityOptions& options, std::mt19937_64& rng) {
  if (!options.Check()) throw std::invalid_argument("KMajority: bad options");
  KMajorityResult result;
  if (selection.empty()) return result;
  result.centers = SeedCenters(descriptors, selection, options.k, rng);
  std::vector<int> assignment(selection.size(), -1);
  // Rounds of assignment then update; a last assignment follows the last update, so every
  // descriptor ends in the cluster of its nearest centre.
  for (int iteration = 0; iteration <= options.max_iterations; ++iteration) {
    bool changed = false;
    for (std::size_t i = 0; i < selection.size(); ++i) {
      const int nearest = Nearest(result.centers, descriptors[selection[i]].data()).first;
      changed |= nearest != assignment[i];
      assignment[i] = nearest;
    }
    result.members.assign(result.centers.size(), {});
    for (std::size_t i = 0; i < selection.size(); ++i) {
      result.members[assignment[i]].push_back(selection[i]);
    }
    if (!changed || iteration == options.max_iterations) break;
    for (std::size_t c = 0; c < result.centers.size(); ++c) {
      if (!result.members[c].empty()) {
        result.centers[c] = MajorityDescriptor(descriptors, result.members[c]);
      }
    }
  }
  // Drop empty clusters; members always agree with the last assignment.
  KMajorityResult compact;
  for (std::size_t c = 0; c < result.centers.size(); ++c) {
    if (result.members[c].empty()) continue;
    compact.centers.push_back(result.centers[c]);
    compact.members.push_back(std::move(result.members[c]));
  }
  return compact;
}

}  // namespace arucoslam
