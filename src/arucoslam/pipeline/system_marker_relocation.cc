// System::RelocateMarkerPoses: at Finish, once markers were mapped during the run, the frames
// whose poses came from markers are located again against the final (refined) marker map,
// and the frames that saw markers but got no pose (an ambiguity not settled yet, markers
// not mapped yet) are located in it too.
#include <algorithm>
#include <set>

#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

void System::RelocateMarkerPoses() {
  if (!marker_mapping_.has_mapper() || !options_.relocate_marker_poses) return;
  const MarkerMap final_map = marker_mapping_.ToMarkerMap();
  const bool any_mapped = std::any_of(final_map.markers.begin(), final_map.markers.end(),
                                      [](const auto& entry) { return !entry.second.fixed; });
  if (!any_mapped) return;  // the frames were located in this map already
  int relocated = 0, late = 0;
  std::set<double> posed;
  for (TrackedPose& pose : poses_) {
    if (pose.in_world || pose.marker_cam_from_world) posed.insert(pose.timestamp_s);
    if (pose.seen_markers.empty()) continue;
    // A keypoint pose outside the world keeps its marker location as its pose; a marker-only
    // or frozen one has no reference keyframe.
    const bool fallback = !pose.in_world && pose.marker_cam_from_world;
    if (!fallback && pose.reference.IsValid()) continue;
    const Rigid3 current = fallback ? *pose.marker_cam_from_world : pose.cam_from_world;
    const std::optional<Rigid3> located =
        marker_fusion_.LocateInMap(pose.seen_markers, final_map, current);
    if (!located) continue;
    if (fallback) {
      pose.marker_cam_from_world = located;
    } else {
      pose.cam_from_world = *located;
      pose.cam_from_reference = *located;
    }
    ++relocated;
  }
  for (const UnposedMarkerFrame& frame : unposed_marker_frames_) {
    if (posed.count(frame.timestamp_s) != 0) continue;  // posed later (a backfill)
    const std::optional<Rigid3> located = marker_fusion_.LocateInMap(frame.markers, final_map, {});
    if (!located) continue;
    TrackedPose pose;
    pose.timestamp_s = frame.timestamp_s;
    pose.cam_from_world = pose.cam_from_reference = *located;
    pose.in_world = true;
    poses_.push_back(std::move(pose));
    ++late;
  }
  unposed_marker_frames_.clear();
  std::stable_sort(poses_.begin(), poses_.end(), [](const TrackedPose& a, const TrackedPose& b) {
    return a.timestamp_s < b.timestamp_s;
  });
  ARUCOSLAM_LOG_DEBUG("final marker map: {} marker poses located again, {} frames posed late",
                      relocated, late);
  std::lock_guard lock(stats_mutex_);
  stats_.num_relocated_marker_poses = relocated;
  stats_.num_late_marker_poses = late;
}

}  // namespace arucoslam
