// CovisibilityGraph: keyframes linked by the number of map points they both observe, plus the
// spanning tree (each keyframe's parent) that keyframe erasure re-parents. Not thread-safe;
// the Map owns one and updates it with every observation it adds or erases.
#pragma once

#include <map>
#include <set>
#include <vector>

#include "arucoslam/map/ids.h"

namespace arucoslam {

class CovisibilityGraph {
 public:
  // Adds a node. `parent` (invalid for the root) becomes its spanning-tree parent.
  void AddKeyframe(KeyframeId id, KeyframeId parent = KeyframeId());
  // Removes a node and its edges; its children are re-parented: repeatedly, the child with
  // the strongest edge to a keyframe already in the tree below the removed one's parent
  // takes that keyframe as parent; children left without any edge go to that parent.
  // Returns false (and changes nothing) for an unknown id or the root of a tree with children.
  bool RemoveKeyframe(KeyframeId id);
  bool Contains(KeyframeId id) const { return nodes_.count(id) != 0; }
  std::size_t NumKeyframes() const { return nodes_.size(); }

  // Changes the weight of the edge a-b by `delta` (shared points +1 / -1). An edge whose
  // weight reaches 0 disappears. Both keyframes must be in the graph.
  void AddToWeight(KeyframeId a, KeyframeId b, int delta);
  int Weight(KeyframeId a, KeyframeId b) const;
  // Neighbours with their weights.
  const std::map<KeyframeId, int>& Neighbours(KeyframeId id) const;
  // Up to `n` neighbours, strongest first (ties: smaller id first).
  std::vector<KeyframeId> BestCovisible(KeyframeId id, int n) const;
  // Every neighbour with weight >= min_weight, strongest first.
  std::vector<KeyframeId> CovisibleWithMinWeight(KeyframeId id, int min_weight) const;

  KeyframeId Parent(KeyframeId id) const;
  const std::set<KeyframeId>& Children(KeyframeId id) const;
  // Re-attaches `child` under `parent` (both present, no cycle: `parent` must not be in the
  // subtree of `child`). Returns false otherwise.
  bool SetParent(KeyframeId child, KeyframeId parent);

 private:
  struct Node {
    std::map<KeyframeId, int> weights;
    KeyframeId parent;
    std::set<KeyframeId> children;
  };
  bool IsInSubtree(KeyframeId candidate, KeyframeId root) const;

  std::map<KeyframeId, Node> nodes_;
};

}  // namespace arucoslam
