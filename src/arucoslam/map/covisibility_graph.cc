#include "arucoslam/map/covisibility_graph.h"

#include <algorithm>
#include <stdexcept>

namespace arucoslam {

void CovisibilityGraph::AddKeyframe(KeyframeId id, KeyframeId parent) {
  if (nodes_.count(id) != 0) throw std::logic_error("CovisibilityGraph: keyframe added twice");
  Node& node = nodes_[id];
  if (parent.IsValid() && nodes_.count(parent) != 0) {
    node.parent = parent;
    nodes_[parent].children.insert(id);
  }
}

bool CovisibilityGraph::RemoveKeyframe(KeyframeId id) {
  const auto it = nodes_.find(id);
  if (it == nodes_.end()) return false;
  Node& node = it->second;
  if (!node.parent.IsValid() && !node.children.empty()) return false;
  for (const auto& [neighbour, weight] : node.weights) nodes_[neighbour].weights.erase(id);

  // Re-parent the children: the parent and every re-attached child are candidates.
  std::set<KeyframeId> candidates;
  if (node.parent.IsValid()) candidates.insert(node.parent);
  std::set<KeyframeId> orphans = node.children;
  while (!orphans.empty()) {
    KeyframeId best_child, best_parent;
    int best_weight = 0;
    for (const KeyframeId& child : orphans) {
      for (const auto& [neighbour, weight] : nodes_[child].weights) {
        if (neighbour != id && candidates.count(neighbour) != 0 && weight > best_weight) {
          best_weight = weight;
          best_child = child;
          best_parent = neighbour;
        }
      }
    }
    if (!best_child.IsValid()) break;
    nodes_[best_child].parent = best_parent;
    nodes_[best_parent].children.insert(best_child);
    candidates.insert(best_child);
    orphans.erase(best_child);
  }
  for (const KeyframeId& child : orphans) {
    nodes_[child].parent = node.parent;
    if (node.parent.IsValid()) nodes_[node.parent].children.insert(child);
  }
  if (node.parent.IsValid()) nodes_[node.parent].children.erase(id);
  nodes_.erase(it);
  return true;
}

void CovisibilityGraph::AddToWeight(KeyframeId a, KeyframeId b, int delta) {
  if (a == b || delta == 0) return;
  const auto it_a = nodes_.find(a);
  const auto it_b = nodes_.find(b);
  if (it_a == nodes_.end() || it_b == nodes_.end()) {
    throw std::logic_error("CovisibilityGraph: edge to an unknown keyframe");
  }
  const int weight = (it_a->second.weights[b] += delta);
  it_b->second.weights[a] = weight;
  if (weight <= 0) {
    it_a->second.weights.erase(b);
    it_b->second.weights.erase(a);
  }
}

int CovisibilityGraph::Weight(KeyframeId a, KeyframeId b) const {
  const auto it = nodes_.find(a);
  if (it == nodes_.end()) return 0;
  const auto edge = it->second.weights.find(b);
  return edge == it->second.weights.end() ? 0 : edge->second;
}

const std::map<KeyframeId, int>& CovisibilityGraph::Neighbours(KeyframeId id) const {
  static const std::map<KeyframeId, int> kEmpty;
  const auto it = nodes_.find(id);
  return it == nodes_.end() ? kEmpty : it->second.weights;
}

namespace {

// The first `n` neighbours of weight `min_weight` or more, heaviest first, ties by id.
std::vector<KeyframeId> HeaviestNeighbours(const std::map<KeyframeId, int>& neighbours,
                                           int min_weight, std::size_t n) {
  std::vector<std::pair<int, KeyframeId>> sorted;
  sorted.reserve(neighbours.size());
  for (const auto& [neighbour, weight] : neighbours) {
    if (weight >= min_weight) sorted.emplace_back(weight, neighbour);
  }
  const auto heavier = [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  };
  n = std::min(n, sorted.size());
  std::partial_sort(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n),
                    sorted.end(), heavier);
  std::vector<KeyframeId> result;
  result.reserve(n);
  for (std::size_t k = 0; k < n; ++k) result.push_back(sorted[k].second);
  return result;
}

}  // namespace

std::vector<KeyframeId> CovisibilityGraph::CovisibleWithMinWeight(KeyframeId id,
                                                                  int min_weight) const {
  return HeaviestNeighbours(Neighbours(id), min_weight, Neighbours(id).size());
}

std::vector<KeyframeId> CovisibilityGraph::BestCovisible(KeyframeId id, int n) const {
  return HeaviestNeighbours(Neighbours(id), 1, static_cast<std::size_t>(std::max(n, 0)));
}

KeyframeId CovisibilityGraph::Parent(KeyframeId id) const {
  const auto it = nodes_.find(id);
  return it == nodes_.end() ? KeyframeId() : it->second.parent;
}

const std::set<KeyframeId>& CovisibilityGraph::Children(KeyframeId id) const {
  static const std::set<KeyframeId> kEmpty;
  const auto it = nodes_.find(id);
  return it == nodes_.end() ? kEmpty : it->second.children;
}

bool CovisibilityGraph::IsInSubtree(KeyframeId candidate, KeyframeId root) const {
  for (KeyframeId walk = candidate; walk.IsValid(); walk = Parent(walk)) {
    if (walk == root) return true;
  }
  return false;
}

bool CovisibilityGraph::SetParent(KeyframeId child, KeyframeId parent) {
  if (!Contains(child) || !Contains(parent) || IsInSubtree(parent, child)) return false;
  Node& node = nodes_[child];
  if (node.parent.IsValid()) nodes_[node.parent].children.erase(child);
  node.parent = parent;
  nodes_[parent].children.insert(child);
  return true;
}

}  // namespace arucoslam
