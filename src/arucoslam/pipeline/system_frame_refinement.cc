// System::RefineFramePoses: at Finish, each tracked frame is optimised again against the final
// map (the points it matched when tracked and its known markers), see refine_frame_poses.
#include <algorithm>
#include <cmath>
#include <vector>

#include "arucoslam/optim/marker_pose_optimizer.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

void System::RefineFramePoses() {
  if (!options_.refine_frame_poses) return;
  const Stopwatch watch;
  int num_refined = 0, num_candidates = 0;
  const PinholeIntrinsics intrinsics = PinholeIntrinsics::FromCamera(camera_);
  map_->Read([&](const MapData& data) {
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
      // refine_min_inlier_fraction of its matches must still be there, and stay inliers.
      const int needed = std::max(
          options_.tracker.min_pose_inliers,
          static_cast<int>(std::ceil(options_.refine_min_inlier_fraction * pose.matches.size())));
      if (static_cast<int>(observations.size()) < needed) continue;
      const Rigid3 start =
          reference ? PoseFromReference(pose, reference->cam_from_world) : pose.cam_from_world;
      MarkerPoseOptimizationOptions optimization = options_.tracker.marker_pose;
      optimization.keypoints = options_.tracker.pose;
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
  std::lock_guard lock(stats_mutex_);
  stats_.num_refined_frame_poses = num_refined;
}

}  // namespace arucoslam
