// System's map merging: a world-aligned map closed after a loss is absorbed by the next map
// once that one is in the world too, with its poses, marker views, priors and place entries.
#include <limits>
#include <vector>

#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

bool System::LinkedToAbsorbedMap() const {
  return map_->Read([&](const MapData& data) {
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

bool System::MergeClosedMap() {
  if (!closed_map_) return false;
  ClosedMap closed = std::move(*closed_map_);
  closed_map_.reset();
  if (closed.data.NumKeyframes() == 0) return false;
  AbsorbedIds ids;
  KeyframeId attach_to;
  const bool merged = map_->Write([&](MapData& data) {
    // The closed map's spanning tree hangs under the current keyframe nearest its root.
    const Eigen::Vector3d root =
        closed.data.FindKeyframe(closed.data.FirstKeyframe())->CameraCenter();
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& [id, keyframe] : data.keyframes()) {
      const double distance = (keyframe.CameraCenter() - root).squaredNorm();
      if (distance < nearest) {
        nearest = distance;
        attach_to = id;
      }
    }
    return attach_to.IsValid() && data.Absorb(closed.data, attach_to, &ids);
  });
  if (!merged) return false;
  // Its keyframes and points are the current map's now, not closed outputs.
  closed_keyframes_.resize(closed.output_keyframes_before);
  closed_points_.resize(closed.output_points_before);
  // Its frozen poses follow their keyframes again.
  int followed = 0;
  map_->Read([&](const MapData& data) {
    for (TrackedPose& pose : poses_) {
      if (!pose.closed_reference.IsValid()) continue;
      const auto found = ids.keyframes.find(pose.closed_reference);
      pose.closed_reference = KeyframeId();
      if (found == ids.keyframes.end()) continue;
      pose.reference = found->second;
      std::vector<FrameMatch> matches;  // its points have new ids here
      for (const FrameMatch& match : pose.matches) {
        const auto point = ids.points.find(match.point);
        if (point != ids.points.end())
          matches.push_back({point->second, match.pixel, match.sigma_px});
      }
      pose.matches = std::move(matches);
      pose.cam_from_reference =
          pose.cam_from_world * data.FindKeyframe(found->second)->cam_from_world.Inverse();
      pose.reference_scale = ReferenceScale(found->second);
      ++followed;
    }
    return 0;
  });
  {
    std::lock_guard lock(keyframe_fixes_mutex_);
    for (const auto& [old_id, fix] : closed.keyframe_fixes) {
      const auto found = ids.keyframes.find(old_id);
      if (found != ids.keyframes.end()) keyframe_fixes_[found->second] = fix;
    }
  }
  int revived = 0;
  if (marker_mapper_ && closed.marker_generation >= 0) {
    revived = marker_mapper_->ReviveClosedMap(closed.marker_generation, ids.keyframes);
  }
  std::vector<KeyframeId> absorbed;
  for (const auto& [old_id, id] : ids.keyframes) {
    absorbed.push_back(id);
    absorbed_keyframes_.insert(id);
  }
  if (places_) places_->IndexKeyframes(absorbed);
  ARUCOSLAM_LOG_DEBUG("closed map merged into the current one: {} keyframes, {} points, {} "
                      "poses follow them, {} with marker views; attached to keyframe {}",
                      ids.keyframes.size(), ids.points.size(), followed, revived,
                      attach_to.value);
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_map_merges;
  return true;
}

}  // namespace arucoslam
