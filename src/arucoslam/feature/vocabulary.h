// Vocabulary: a tree of binary ORB words (hierarchical k-majority, branching k, depth L) with
// TF-IDF weights; Transform() turns an image's descriptors into a BowVector and direct index.
#pragma once

#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "arucoslam/feature/binary_kmeans.h"
#include "arucoslam/feature/bow_vector.h"

namespace arucoslam {

struct VocabularyOptions {
  int branching = 10;       // k: children per node (>= 2)
  int levels = 5;           // L: depth of the leaves below the root (1..8); k^L words at most
  int max_iterations = 10;  // k-majority rounds per node
  std::uint64_t seed = 1;   // seed of the k-means++ choices (training is deterministic)
  bool Check(std::string* why = nullptr) const;
};

class Vocabulary {
 public:
  struct Node {
    NodeId parent = 0;               // root: itself (0)
    NodeId first_child = 0;          // children are contiguous: first_child .. +num_children-1
    std::uint32_t num_children = 0;  // 0 for a leaf (a word)
    std::uint32_t depth = 0;         // root 0, its children 1, ...
    WordId word = 0;                 // leaves only: index of the word
    double weight = 0.0;             // leaves only: idf = ln(N / n_w) over the training images
    BinaryDescriptor descriptor{};   // cluster centre (root: zeros)
    friend bool operator==(const Node&, const Node&) = default;
  };

  Vocabulary() = default;

  // Trains on the descriptors of a set of images (each n x 32 CV_8U; an empty Mat is an image
  // without features): hierarchical k-majority, then idf weights. Throws std::invalid_argument
  // for bad options or descriptor matrices, and when there is no descriptor at all.
  static Vocabulary Train(const std::vector<cv::Mat>& descriptors_per_image,
                          const VocabularyOptions& options);

  // Binary file (format at the top of vocabulary_io.cc). Load throws
  // InputError naming the file for a missing file, wrong magic or version, a truncated or
  // corrupted file; Save throws InputError when the file cannot be written (atomic write).
  static Vocabulary Load(const std::filesystem::path& path);
  void Save(const std::filesystem::path& path) const;
  // Same format in memory; `source` names the data in errors.
  static Vocabulary FromBytes(const std::string& bytes, const std::string& source);
  std::string ToBytes() const;

  // Word of one 32-byte descriptor: from the root, the child with the nearest centre (lowest
  // index on ties) down to a leaf. When `node_at_depth` is given it receives the node passed at
  // `depth` (the leaf itself when the leaf is shallower).
  WordId Transform(const std::uint8_t* descriptor, NodeId* node_at_depth = nullptr,
                   int depth = 0) const;
  // BoW vector of an image (n x 32 CV_8U): idf weight summed per word, L1-normalised; words
  // of zero weight (in every training image) are left out.
  BowVector Transform(const cv::Mat& descriptors) const;
  // Same, plus the direct index: features grouped by their node at `direct_index_depth`
  // (1 .. levels; the coarser the level, the more candidates per group).
  void Transform(const cv::Mat& descriptors, int direct_index_depth, BowVector* bow,
                 FeatureVector* direct) const;

  bool empty() const { return words_.empty(); }
  int branching() const { return branching_; }
  int levels() const { return levels_; }
  std::size_t num_words() const { return words_.size(); }
  std::size_t num_nodes() const { return nodes_.size(); }
  std::uint32_t num_training_images() const { return num_training_images_; }
  const Node& node(NodeId id) const { return nodes_.at(id); }
  NodeId WordNode(WordId word) const { return words_.at(word); }
  double WordWeight(WordId word) const { return nodes_[words_.at(word)].weight; }

  friend bool operator==(const Vocabulary&, const Vocabulary&) = default;

 private:
  // Rebuilds first_child/num_children/depth/word and words_ from the parents; checks the
  // tree shape (parents precede children, siblings contiguous, depth <= levels_).
  void LinkTree(const std::string& source);

  int branching_ = 0;
  int levels_ = 0;
  std::uint32_t num_training_images_ = 0;
  std::vector<Node> nodes_;    // breadth-first; nodes_[0] is the root
  std::vector<NodeId> words_;  // leaf node of each word, in node order
};

}  // namespace arucoslam
