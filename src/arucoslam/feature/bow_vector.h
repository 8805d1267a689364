// BowVector (word -> tf-idf weight, L1-normalised) and FeatureVector (direct index: vocabulary
// node -> features under it) of one image, with the L1 similarity score used for place search.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace arucoslam {

// Index of a leaf of a Vocabulary (0 .. num_words-1).
using WordId = std::uint32_t;
// Index of any node of a Vocabulary (0 = root).
using NodeId = std::uint32_t;

// Sparse bag-of-words vector: entries sorted by word, each word once, weights > 0.
struct BowVector {
  struct Entry {
    WordId word = 0;
    double weight = 0.0;
    friend bool operator==(const Entry&, const Entry&) = default;
  };
  std::vector<Entry> entries;

  bool empty() const { return entries.empty(); }
  std::size_t size() const { return entries.size(); }
  // Sum of the weights (1 after Normalize(), 0 when empty).
  double L1Norm() const;
  // Divides every weight by L1Norm() (no-op when empty).
  void Normalize();
  // Builds a vector from unsorted (word, weight) pairs: sums repeated words, drops weights
  // <= 0 and sorts by word. Not normalised.
  static BowVector FromPairs(std::vector<std::pair<WordId, double>> pairs);
};

// L1 similarity of two L1-normalised vectors: 1 - 0.5 * |a - b|_1, in [0, 1]; 1 for equal
// vectors, 0 when they share no word.
double L1Score(const BowVector& a, const BowVector& b);

// Direct index of one image: for each vocabulary node at the chosen level, the indices of
// the image's features whose descriptors descend through it. Sorted by node; features in
// ascending order. Two images' features only need comparing inside a shared node.
struct FeatureVector {
  struct Group {
    NodeId node = 0;
    std::vector<int> features;
    friend bool operator==(const Group&, const Group&) = default;
  };
  std::vector<Group> groups;

  // Builds the groups from one node per feature (node_of_feature[i] for feature i; features
  // with a negative entry are left out).
  static FeatureVector FromNodes(const std::vector<std::int64_t>& node_of_feature);
  // The group of `node`, or nullptr.
  const Group* Find(NodeId node) const;
};

// Pairs of feature indices (a, b) that share a node in both direct indexes: the candidate
// matches between two images, to be checked by descriptor distance.
std::vector<std::pair<int, int>> CandidatePairs(const FeatureVector& a, const FeatureVector& b);

}  // namespace arucoslam
