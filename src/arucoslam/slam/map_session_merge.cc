// MapSession's merge: a world-aligned map closed after a loss is absorbed by the next map once
// that one is in the world too; its keyframes and points leave the closed outputs.
#include <limits>
#include <utility>

#include "arucoslam/slam/map_session.h"

namespace arucoslam {
namespace {

// The keyframe of `data` whose camera centre is nearest `point` (invalid: no keyframe).
KeyframeId NearestKeyframe(const MapData& data, const Eigen::Vector3d& point) {
  KeyframeId nearest;
  double nearest_sq = std::numeric_limits<double>::infinity();
  for (const auto& [id, keyframe] : data.keyframes()) {
    const double distance_sq = (keyframe.CameraCenter() - point).squaredNorm();
    if (distance_sq < nearest_sq) {
      nearest_sq = distance_sq;
      nearest = id;
    }
  }
  return nearest;
}

}  // namespace

std::optional<MergedClosedMap> MapSession::MergeClosedMap(Map& map) {
  if (!closed_map_) return std::nullopt;
  ClosedMap closed = std::move(*closed_map_);
  closed_map_.reset();
  if (closed.data.NumKeyframes() == 0) return std::nullopt;
  MergedClosedMap merged;
  const bool absorbed = map.Write([&](MapData& data) {
    // The closed map's spanning tree hangs under the current keyframe nearest its root.
    const Eigen::Vector3d root =
        closed.data.FindKeyframe(closed.data.FirstKeyframe())->CameraCenter();
    merged.attached_to = NearestKeyframe(data, root);
    return merged.attached_to.IsValid() &&
           data.Absorb(closed.data, merged.attached_to, &merged.ids);
  });
  if (!absorbed) return std::nullopt;
  // Its keyframes and points are the current map's now, not closed outputs.
  closed_keyframes_.resize(closed.output_keyframes_before);
  closed_points_.resize(closed.output_points_before);
  for (const auto& [old_id, fix] : closed.keyframe_fixes) {
    const auto found = merged.ids.keyframes.find(old_id);
    if (found != merged.ids.keyframes.end()) merged.keyframe_fixes[found->second] = fix;
  }
  for (const auto& [old_id, id] : merged.ids.keyframes) absorbed_keyframes_.insert(id);
  merged.marker_generation = closed.marker_generation;
  ++stats_.num_map_merges;
  return merged;
}

bool MapSession::LinkedToAbsorbedMap(const Map& map) const {
  return map.Read([&](const MapData& data) {
    for (const auto& [id, point] : data.map_points()) {
      bool absorbed = false, current = false;
      for (const auto& [keyframe, index] : point.observations) {
        (absorbed_keyframes_.count(keyframe) != 0 ? absorbed : current) = true;
      }
      if (absorbed && current) return true;
    }
    return false;
  });
}

}  // namespace arucoslam
