#include "arucoslam/feature/vocabulary.h"

#include <cmath>
#include <deque>
#include <limits>
#include <random>
#include <stdexcept>
#include <utility>

#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

void CheckDescriptorMatrix(const cv::Mat& descriptors) {
  if (descriptors.empty()) return;
  if (descriptors.type() != CV_8UC1 || descriptors.cols != kOrbDescriptorBytes) {
    throw std::invalid_argument("Vocabulary: descriptors must be n x 32 CV_8U");
  }
}

}  // namespace

bool VocabularyOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.InRange("branching", branching, 2, 255, Interval::kClosed);
  check.InRange("levels", levels, 1, 8, Interval::kClosed);
  check.AtLeast("max_iterations", max_iterations, 1);
  return check.ok();
}

Vocabulary Vocabulary::Train(const std::vector<cv::Mat>& descriptors_per_image,
                             const VocabularyOptions& options) {
  if (!options.Check()) throw std::invalid_argument("Vocabulary::Train: bad options");
  std::vector<BinaryDescriptor> all;
  for (const cv::Mat& descriptors : descriptors_per_image) {
    CheckDescriptorMatrix(descriptors);
    for (int r = 0; r < descriptors.rows; ++r) {
      BinaryDescriptor d;
      std::memcpy(d.data(), descriptors.ptr<std::uint8_t>(r), kOrbDescriptorBytes);
      all.push_back(d);
    }
  }
  if (all.empty()) throw std::invalid_argument("Vocabulary::Train: no descriptors");
  if (all.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("Vocabulary::Train: too many descriptors");
  }

  Vocabulary vocabulary;
  vocabulary.branching_ = options.branching;
  vocabulary.levels_ = options.levels;
  vocabulary.num_training_images_ = static_cast<std::uint32_t>(descriptors_per_image.size());
  vocabulary.nodes_.push_back(Node{});
  std::mt19937_64 rng(options.seed);
  const KMajorityOptions kmajority{options.branching, options.max_iterations};

  // Breadth-first: the children of each node are appended together, so they are contiguous
  // and parents never decrease along the node array.
  std::deque<std::pair<NodeId, std::vector<std::uint32_t>>> pending;
  std::vector<std::uint32_t> everything(all.size());
  for (std::size_t i = 0; i < all.size(); ++i) everything[i] = static_cast<std::uint32_t>(i);
  pending.emplace_back(0, std::move(everything));
  while (!pending.empty()) {
    auto [id, members] = std::move(pending.front());
    pending.pop_front();
    const std::uint32_t depth = vocabulary.nodes_[id].depth;
    if (static_cast<int>(depth) >= options.levels || members.size() <= 1) continue;
    KMajorityResult clusters = KMajority(all, members, kmajority, rng);
    members = {};
    if (clusters.centers.size() <= 1) continue;  // all identical: a leaf
    for (std::size_t c = 0; c < clusters.centers.size(); ++c) {
      Node child;
      child.parent = id;
      child.depth = depth + 1;
      child.descriptor = clusters.centers[c];
      vocabulary.nodes_.push_back(child);
      pending.emplace_back(static_cast<NodeId>(vocabulary.nodes_.size() - 1),
                           std::move(clusters.members[c]));
    }
  }
  if (vocabulary.nodes_.size() < 2) {
    throw std::invalid_argument("Vocabulary::Train: fewer than 2 distinct descriptors");
  }
  vocabulary.LinkTree("training");

  // idf: ln(N / n_w), n_w = training images in which word w occurs at least once.
  std::vector<std::uint32_t> images_with_word(vocabulary.words_.size(), 0);
  std::vector<std::uint32_t> last_image(vocabulary.words_.size(),
                                        std::numeric_limits<std::uint32_t>::max());
  for (std::uint32_t image = 0; image < descriptors_per_image.size(); ++image) {
    const cv::Mat& descriptors = descriptors_per_image[image];
    for (int r = 0; r < descriptors.rows; ++r) {
      const WordId word = vocabulary.Transform(descriptors.ptr<std::uint8_t>(r));
      if (last_image[word] != image) {
        last_image[word] = image;
        ++images_with_word[word];
      }
    }
  }
  const double num_images = static_cast<double>(descriptors_per_image.size());
  for (std::size_t w = 0; w < vocabulary.words_.size(); ++w) {
    // A word no training image reaches by descent (possible at cluster borders) is as rare
    // as one seen once.
    const double n = std::max<std::uint32_t>(images_with_word[w], 1);
    vocabulary.nodes_[vocabulary.words_[w]].weight = std::log(num_images / n);
  }
  return vocabulary;
}

WordId Vocabulary::Transform(const std::uint8_t* descriptor, NodeId* node_at_depth,
                             int depth) const {
  NodeId id = 0;
  if (node_at_depth != nullptr) *node_at_depth = 0;
  while (nodes_[id].num_children > 0) {
    const Node& node = nodes_[id];
    NodeId best = node.first_child;
    int best_distance = std::numeric_limits<int>::max();
    for (NodeId child = node.first_child; child < node.first_child + node.num_children; ++child) {
      const int distance = DescriptorDistance(nodes_[child].descriptor.data(), descriptor);
      if (distance < best_distance) {
        best_distance = distance;
        best = child;
      }
    }
    id = best;
    if (node_at_depth != nullptr && static_cast<int>(nodes_[id].depth) <= depth) {
      *node_at_depth = id;
    }
  }
  return nodes_[id].word;
}

BowVector Vocabulary::Transform(const cv::Mat& descriptors) const {
  BowVector bow;
  Transform(descriptors, 0, &bow, nullptr);
  return bow;
}

void Vocabulary::Transform(const cv::Mat& descriptors, int direct_index_depth, BowVector* bow,
                           FeatureVector* direct) const {
  CheckDescriptorMatrix(descriptors);
  std::vector<std::pair<WordId, double>> pairs;
  std::vector<std::int64_t> node_of_feature;
  if (!empty()) {
    pairs.reserve(descriptors.rows);
    node_of_feature.reserve(descriptors.rows);
    for (int r = 0; r < descriptors.rows; ++r) {
      NodeId node = 0;
      const WordId word = Transform(descriptors.ptr<std::uint8_t>(r),
                                    direct != nullptr ? &node : nullptr, direct_index_depth);
      pairs.emplace_back(word, nodes_[words_[word]].weight);
      node_of_feature.push_back(node);
    }
  }
  if (bow != nullptr) {
    *bow = BowVector::FromPairs(std::move(pairs));
    bow->Normalize();
  }
  if (direct != nullptr) *direct = FeatureVector::FromNodes(node_of_feature);
}

}  // namespace arucoslam
