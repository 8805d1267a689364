// MapData::CheckInvariants: a full walk over the map that recomputes what the incremental
// bookkeeping maintains and reports the first disagreement.
#include <fmt/format.h>

#include <map>
#include <set>
#include <utility>

#include "arucoslam/map/map_data.h"

namespace arucoslam {

std::string MapData::CheckInvariants() const {
  // Keyframe slots -> point observations.
  for (const auto& [keyframe_id, keyframe] : keyframes_.map()) {
    if (keyframe.id != keyframe_id) return fmt::format("keyframe {}: wrong id", keyframe_id.value);
    for (std::size_t i = 0; i < keyframe.map_point_ids.size(); ++i) {
      const MapPointId point_id = keyframe.map_point_ids[i];
      if (!point_id.IsValid()) continue;
      const MapPoint* point = FindMapPoint(point_id);
      if (point == nullptr) {
        return fmt::format("keyframe {} slot {}: unknown point {}", keyframe_id.value, i,
                           point_id.value);
      }
      const auto it = point->observations.find(keyframe_id);
      if (it == point->observations.end() || it->second != static_cast<int>(i)) {
        return fmt::format("keyframe {} slot {}: point {} does not list it", keyframe_id.value, i,
                           point_id.value);
      }
    }
  }
  // Point observations -> keyframe slots; recount the covisibility weights.
  std::map<std::pair<KeyframeId, KeyframeId>, int> shared;
  for (const auto& [point_id, point] : points_.map()) {
    for (const auto& [keyframe_id, index] : point.observations) {
      const Keyframe* keyframe = FindKeyframe(keyframe_id);
      if (keyframe == nullptr || index < 0 ||
          index >= static_cast<int>(keyframe->map_point_ids.size()) ||
          keyframe->map_point_ids[index] != point_id) {
        return fmt::format("point {}: observation by keyframe {} index {} not mirrored",
                           point_id.value, keyframe_id.value, index);
      }
      for (const auto& [other, other_index] : point.observations) {
        if (keyframe_id < other) ++shared[{keyframe_id, other}];
      }
    }
  }
  for (const auto& [keyframe_id, keyframe] : keyframes_.map()) {
    if (!graph_.Contains(keyframe_id)) {
      return fmt::format("keyframe {}: not in the graph", keyframe_id.value);
    }
    for (const auto& [other, weight] : graph_.Neighbours(keyframe_id)) {
      const auto key = keyframe_id < other ? std::make_pair(keyframe_id, other)
                                           : std::make_pair(other, keyframe_id);
      const auto it = shared.find(key);
      const int expected = it == shared.end() ? 0 : it->second;
      if (weight != expected || graph_.Weight(other, keyframe_id) != weight) {
        return fmt::format("edge {}-{}: weight {}, shared points {}", keyframe_id.value,
                           other.value, weight, expected);
      }
    }
    // Spanning tree: a parent for all but the first, parent lists the child, no cycle.
    const KeyframeId parent = graph_.Parent(keyframe_id);
    if (keyframe_id != first_keyframe_ && !parent.IsValid()) {
      return fmt::format("keyframe {}: no spanning-tree parent", keyframe_id.value);
    }
    if (parent.IsValid() && graph_.Children(parent).count(keyframe_id) == 0) {
      return fmt::format("keyframe {}: parent {} does not list it", keyframe_id.value,
                         parent.value);
    }
    std::set<KeyframeId> seen;
    for (KeyframeId walk = keyframe_id; walk.IsValid(); walk = graph_.Parent(walk)) {
      if (!seen.insert(walk).second) {
        return fmt::format("keyframe {}: cycle in the spanning tree", keyframe_id.value);
      }
    }
  }
  for (const auto& [key, count] : shared) {
    if (graph_.Weight(key.first, key.second) != count) {
      return fmt::format("edge {}-{}: missing (shared points {})", key.first.value,
                         key.second.value, count);
    }
  }
  if (graph_.NumKeyframes() != keyframes_.size()) return "graph and keyframes differ in size";
  return {};
}

}  // namespace arucoslam
