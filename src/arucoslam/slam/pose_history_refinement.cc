// PoseHistory at the end of a run: the poses refined against the final map, and located
// again in the final marker map.
#include <algorithm>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include "arucoslam/slam/pose_history.h"
#include "arucoslam/util/logging.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {

int PoseHistory::RefineAgainstMap(const Map& map, const PinholeIntrinsics& intrinsics,
                                  const FramePoseRefinement& refinement) {
  const Stopwatch watch;
  int num_refined = 0, num_candidates = 0;
  map.Read([&](const MapData& data) {
    std::vector<PoseObservation> observations;
    for (TrackedPose& pose : poses_) {
      // A valid reference means the pose belongs to the current map, as its matches do. A
      // culled reference that was not re-anchored leaves the pose as it was recorded.
      if (!pose.reference.IsValid() || pose.matches.empty()) continue;
      const Keyframe* reference = data.FindKeyframe(pose.reference);
      ++num_candidates;
      observations.clear();
      for (const FrameMatch& match : pose.matches) {
        const MapPoint* point = data.FindMapPoint(match.point);
        if (point == nullptr) continue;
        observations.push_back({point->p_in_world, match.pixel.cast<double>(), match.sigma_px});
      }
      // Points culled or fused since the frame was tracked are gone: at least
      // min_inlier_fraction of its matches must still be there, and stay inliers.
      const int needed = std::max(
          refinement.min_inliers,
          static_cast<int>(std::ceil(refinement.min_inlier_fraction * pose.matches.size())));
      if (static_cast<int>(observations.size()) < needed) continue;
      const Rigid3 start =
          reference ? PoseFromReference(pose, reference->cam_from_world) : pose.cam_from_world;
      MarkerPoseOptimizationOptions optimization = refinement.optimization;
      optimization.keypoints.min_inliers = needed;
      // Without markers this is OptimizePose.
      const MarkerPoseOptimizationResult result =
          OptimizePoseWithMarkers(observations, pose.markers, start, intrinsics, optimization);
      if (!result.success || result.num_inliers < needed) continue;
      const Rigid3& refined = result.cam_from_world;
      pose.cam_from_world = refined;
      if (reference != nullptr) {
        pose.cam_from_reference = refined * reference->cam_from_world.Inverse();
        pose.reference_scale = ReferenceScale(pose.reference);
      }
      ++num_refined;
    }
    return 0;
  });
  for (TrackedPose& pose : poses_) {
    pose.matches = {};
    pose.markers = {};
  }
  ARUCOSLAM_LOG_DEBUG("frame poses refined against the final map: {} of {} ({:.0f} ms)",
                      num_refined, num_candidates, watch.ElapsedMilliseconds());
  return num_refined;
}

std::optional<MarkerRelocationCounts> PoseHistory::RelocateInMarkerMap(const MarkerMap& final_map,
                                                                       const MarkerFusion& fusion) {
  const bool any_mapped = std::any_of(final_map.markers.begin(), final_map.markers.end(),
                                      [](const auto& entry) { return !entry.second.fixed; });
  if (!any_mapped) return std::nullopt;  // the frames were located in this map already
  MarkerRelocationCounts counts;
  std::set<double> posed;
  for (TrackedPose& pose : poses_) {
    if (pose.in_world || pose.marker_cam_from_world) posed.insert(pose.timestamp_s);
    if (pose.seen_markers.empty()) continue;
    // A keypoint pose outside the world keeps its marker location as its pose; a marker-only
    // or frozen one has no reference keyframe.
    const bool fallback = !pose.in_world && pose.marker_cam_from_world;
    if (!fallback && pose.reference.IsValid()) continue;
    const Rigid3 current = fallback ? *pose.marker_cam_from_world : pose.cam_from_world;
    const std::optional<Rigid3> located = fusion.LocateInMap(pose.seen_markers, final_map, current);
    if (!located) continue;
    if (fallback) {
      pose.marker_cam_from_world = located;
    } else {
      pose.cam_from_world = *located;
      pose.cam_from_reference = *located;
    }
    ++counts.num_relocated;
  }
  for (const UnposedMarkerFrame& frame : unposed_marker_frames_) {
    if (posed.count(frame.timestamp_s) != 0) continue;  // posed later (a backfill)
    const std::optional<Rigid3> located = fusion.LocateInMap(frame.markers, final_map, {});
    if (!located) continue;
    TrackedPose pose;
    pose.timestamp_s = frame.timestamp_s;
    pose.cam_from_world = pose.cam_from_reference = *located;
    pose.in_world = true;
    poses_.push_back(std::move(pose));
    ++counts.num_late;
  }
  unposed_marker_frames_.clear();
  SortByTime();
  ARUCOSLAM_LOG_DEBUG("final marker map: {} marker poses located again, {} frames posed late",
                      counts.num_relocated, counts.num_late);
  return counts;
}

}  // namespace arucoslam
