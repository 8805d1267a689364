#include "arucoslam/slam/marker_candidates.h"

#include <algorithm>
#include <map>
#include <set>
#include <utility>

namespace arucoslam {

std::vector<KeyframeId> KeyframesSeeingMarkers(const MapData& data,
                                               const std::vector<MarkerObservation>& markers,
                                               int max_candidates) {
  std::set<MarkerId> wanted;
  for (const MarkerObservation& marker : markers) wanted.insert(marker.marker_id);
  std::vector<std::pair<int, KeyframeId>> shared;  // (ids in common, keyframe)
  if (wanted.empty()) return {};
  for (const auto& [id, keyframe] : data.keyframes()) {
    std::set<MarkerId> common;
    for (const MarkerObservation& marker : keyframe.markers) {
      if (wanted.count(marker.marker_id) != 0) common.insert(marker.marker_id);
    }
    if (!common.empty()) shared.emplace_back(static_cast<int>(common.size()), id);
  }
  std::sort(shared.begin(), shared.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second > b.second;
  });
  std::vector<KeyframeId> candidates;
  for (const auto& [count, id] : shared) {
    if (static_cast<int>(candidates.size()) >= max_candidates) break;
    candidates.push_back(id);
  }
  return candidates;
}

}  // namespace arucoslam
