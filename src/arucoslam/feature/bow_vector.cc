#include "arucoslam/feature/bow_vector.h"

#include <algorithm>
#include <cmath>

namespace arucoslam {

double BowVector::L1Norm() const {
  double sum = 0.0;
  for (const Entry& entry : entries) sum += std::abs(entry.weight);
  return sum;
}

void BowVector::Normalize() {
  const double norm = L1Norm();
  if (norm <= 0.0) return;
  for (Entry& entry : entries) entry.weight /= norm;
}

BowVector BowVector::FromPairs(std::vector<std::pair<WordId, double>> pairs) {
  std::sort(pairs.begin(), pairs.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  BowVector vector;
  for (const auto& [word, weight] : pairs) {
    if (!vector.entries.empty() && vector.entries.back().word == word) {
      vector.entries.back().weight += weight;
    } else {
      vector.entries.push_back({word, weight});
    }
  }
  std::erase_if(vector.entries, [](const Entry& entry) { return !(entry.weight > 0.0); });
  return vector;
}

double L1Score(const BowVector& a, const BowVector& b) {
  // For non-negative vectors with |a|_1 = |b|_1 = 1:
  // 1 - 0.5 |a - b|_1 = 0.5 * sum over shared words of (|a_w| + |b_w| - |a_w - b_w|).
  double shared = 0.0;
  auto ia = a.entries.begin();
  auto ib = b.entries.begin();
  while (ia != a.entries.end() && ib != b.entries.end()) {
    if (ia->word < ib->word) {
      ++ia;
    } else if (ib->word < ia->word) {
      ++ib;
    } else {
      shared += std::abs(ia->weight) + std::abs(ib->weight) - std::abs(ia->weight - ib->weight);
      ++ia;
      ++ib;
    }
  }
  return std::clamp(0.5 * shared, 0.0, 1.0);
}

FeatureVector FeatureVector::FromNodes(const std::vector<std::int64_t>& node_of_feature) {
  std::vector<std::pair<NodeId, int>> pairs;
  pairs.reserve(node_of_feature.size());
  for (std::size_t i = 0; i < node_of_feature.size(); ++i) {
    if (node_of_feature[i] >= 0) {
      pairs.emplace_back(static_cast<NodeId>(node_of_feature[i]), static_cast<int>(i));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  FeatureVector vector;
  for (const auto& [node, feature] : pairs) {
    if (vector.groups.empty() || vector.groups.back().node != node) {
      vector.groups.push_back({node, {}});
    }
    vector.groups.back().features.push_back(feature);
  }
  return vector;
}

const FeatureVector::Group* FeatureVector::Find(NodeId node) const {
  const auto it = std::lower_bound(groups.begin(), groups.end(), node,
                                   [](const Group& group, NodeId n) { return group.node < n; });
  return it != groups.end() && it->node == node ? &*it : nullptr;
}

std::vector<std::pair<int, int>> CandidatePairs(const FeatureVector& a, const FeatureVector& b) {
  std::vector<std::pair<int, int>> pairs;
  auto ia = a.groups.begin();
  auto ib = b.groups.begin();
  while (ia != a.groups.end() && ib != b.groups.end()) {
    if (ia->node < ib->node) {
      ++ia;
    } else if (ib->node < ia->node) {
      ++ib;
    } else {
      for (int fa : ia->features) {
        for (int fb : ib->features) pairs.emplace_back(fa, fb);
      }
      ++ia;
      ++ib;
    }
  }
  return pairs;
}

}  // namespace arucoslam
