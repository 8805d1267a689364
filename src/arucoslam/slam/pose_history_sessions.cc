// PoseHistory across the map's sessions: the alignment to the marker world, the reset that
// freezes the poses in the world, and the merge that lets a closed map's poses follow again.
#include <utility>
#include <vector>

#include "arucoslam/slam/pose_history.h"

namespace arucoslam {

void PoseHistory::MoveIntoWorld(const Sim3& world_from_map, bool realigned,
                                const std::set<KeyframeId>& absorbed) {
  for (TrackedPose& pose : poses_) {
    // Marker-only and frozen poses (no reference) are in the world already; on a
    // re-alignment the poses tied to this map's keyframes move with them.
    const bool moves = !pose.in_world || (realigned && pose.reference.IsValid() &&
                                          absorbed.count(pose.reference) == 0);
    if (!moves) continue;
    pose.cam_from_world = world_from_map.TransformPose(pose.cam_from_world.Inverse()).Inverse();
    pose.cam_from_reference.translation *= world_from_map.scale;
    pose.in_world = true;
  }
}

void PoseHistory::FreezeForReset(const Map& map, bool kept_for_merge) {
  std::vector<TrackedPose> kept;
  map.Read([&](const MapData& data) {
    for (TrackedPose pose : poses_) {
      if (!pose.in_world && pose.marker_cam_from_world) {  // frozen at its marker location
        pose.cam_from_world = *pose.marker_cam_from_world;
        pose.cam_from_reference = pose.cam_from_world;
        pose.reference = KeyframeId();
        pose.in_world = true;
      }
      if (!pose.in_world) continue;
      if (kept_for_merge) pose.closed_reference = KeyframeId();  // an older closed map's
      if (const Keyframe* reference = data.FindKeyframe(pose.reference)) {
        pose.cam_from_world = PoseFromReference(pose, reference->cam_from_world);
        if (kept_for_merge) pose.closed_reference = pose.reference;
      }
      pose.reference = KeyframeId();
      if (!pose.closed_reference.IsValid()) {  // frozen for good: never refined
        pose.matches = {};
        pose.markers = {};
      }
      kept.push_back(std::move(pose));
    }
    return 0;
  });
  poses_ = std::move(kept);
}

int PoseHistory::FollowMergedMap(const Map& map, const AbsorbedIds& ids) {
  int followed = 0;
  map.Read([&](const MapData& data) {
    for (TrackedPose& pose : poses_) {
      if (!pose.closed_reference.IsValid()) continue;
      const auto found = ids.keyframes.find(pose.closed_reference);
      pose.closed_reference = KeyframeId();
      if (found == ids.keyframes.end()) continue;
      pose.reference = found->second;
      std::vector<FrameMatch> matches;  // its points have new ids here
      for (const FrameMatch& match : pose.matches) {
        const auto point = ids.points.find(match.point);
        if (point != ids.points.end()) {
          matches.push_back({point->second, match.pixel, match.sigma_px});
        }
      }
      pose.matches = std::move(matches);
      pose.cam_from_reference =
          pose.cam_from_world * data.FindKeyframe(found->second)->cam_from_world.Inverse();
      pose.reference_scale = ReferenceScale(found->second);
      ++followed;
    }
    return 0;
  });
  return followed;
}

}  // namespace arucoslam
