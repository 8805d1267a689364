// System's bridge over a tracking gap: the world-aligned map closed after a loss predicts,
// from the camera's motion at its end, where the next map's first keyframe is; once both maps
// are merged in the world, that prediction ties the new map's start in one pose-graph
// correction (later corrections keep the shape it gave).
#include <vector>

#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

void System::RememberMotionAtClose() {
  motion_at_close_.Clear();
  if (!options_.bridge_tracking_gaps) return;
  // Frames off their keyframes (a plain wall before the loss) would bend the velocity.
  const std::vector<StampedPose> poses = DropPosesOffTheirKeyframes(
      CurrentMapPoses(/*world_only=*/true), KeyframePoses(), options_.pose_consistency);
  for (const StampedPose& pose : poses) motion_at_close_.Add(pose.timestamp_s, pose.world_from_cam);
}

void System::AddBridgePrior(KeyframeId keyframe, double timestamp_s) {
  if (!options_.bridge_tracking_gaps || !closed_map_ || world_aligned_) return;
  const std::optional<Rigid3> predicted = motion_at_close_.Predict(timestamp_s);
  if (!predicted) return;
  const double gap_s = timestamp_s - *motion_at_close_.NewestTimestamp();
  const double position_sigma =
      options_.bridge_position_sigma_m + options_.bridge_position_sigma_per_s * gap_s;
  const double rotation_sigma =
      options_.bridge_rotation_sigma_rad + options_.bridge_rotation_sigma_per_s * gap_s;
  KeyframePosePrior prior;
  prior.keyframe = keyframe;
  prior.world_from_cam = *predicted;
  prior.information = Matrix6d::Zero();
  prior.information.topLeftCorner<3, 3>().diagonal().setConstant(1.0 /
                                                                 (position_sigma * position_sigma));
  prior.information.bottomRightCorner<3, 3>().diagonal().setConstant(
      1.0 / (rotation_sigma * rotation_sigma));
  bridge_priors_.push_back(prior);
  // For the bundle adjustments: how far a vehicle accelerating at most at the bound can
  // stray from the constant-velocity prediction over the gap.
  const double adjustment_sigma = options_.bridge_position_sigma_m +
                                  0.5 * options_.bridge_max_acceleration_m_s2 * gap_s * gap_s;
  prior.information.topLeftCorner<3, 3>().diagonal().setConstant(
      1.0 / (adjustment_sigma * adjustment_sigma));
  bridge_adjustment_priors_.push_back(prior);
  ARUCOSLAM_LOG_DEBUG(
      "keyframe {}: bridged over {:.2f} s from the closed map (sigma {:.2f} m, "
      "{:.2f} rad; {:.2f} m in bundle adjustment)",
      keyframe.value, gap_s, position_sigma, rotation_sigma, adjustment_sigma);
}

bool System::CorrectAcrossBridge() {
  if (bridge_priors_.empty()) return false;
  std::vector<KeyframePosePrior> priors = KnownMarkerPriors();
  priors.insert(priors.end(), bridge_priors_.begin(), bridge_priors_.end());
  bridge_priors_.clear();
  std::vector<KeyframePosePrior> adjustment_priors = std::move(bridge_adjustment_priors_);
  bridge_adjustment_priors_.clear();
  if (places_) places_->MapMovedExternally();
  // The absorbed map is in the world already (adjusted with its markers when it was
  // closed): only the new map bends, between the bridge at its start and its markers.
  const EssentialGraphResult result = OptimizeEssentialGraph(
      *map_, KeyframeId(), {}, {}, priors, options_.marker_correction_graph, absorbed_keyframes_);
  ARUCOSLAM_LOG_DEBUG(
      "merged map corrected across the tracking gap over {} keyframes with {} "
      "priors, {} absorbed keyframes held: {}",
      result.num_keyframes, result.num_priors, absorbed_keyframes_.size(),
      result.summary.BriefReport());
  if (!result.applied) return false;
  if (options_.bridge_in_bundle_adjustment) {
    adjustment_priors.insert(adjustment_priors.begin(), held_bridge_priors_.begin(),
                             held_bridge_priors_.end());
    HoldBridgePriors(std::move(adjustment_priors));
  }
  if (places_) places_->RecordScaleChanges(result.scale_changes);
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_bridged_gaps;
  return true;
}

void System::HoldBridgePriors(std::vector<KeyframePosePrior> priors) {
  held_bridge_priors_ = std::move(priors);
  if (marker_mapper_) marker_mapper_->SetPositionPriors(held_bridge_priors_);
  if (places_) places_->SetBundleAdjustmentPriors(held_bridge_priors_);
}

}  // namespace arucoslam
