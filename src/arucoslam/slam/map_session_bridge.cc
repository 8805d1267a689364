// MapSession's bridge over a tracking gap: the world-aligned map closed after a loss predicts,
// from the camera's motion at its end, where the next map's first keyframe is; once both maps
// are merged in the world, that prediction ties the new map's start in one pose-graph
// correction (later corrections keep the shape it gave).
#include <utility>
#include <vector>

#include "arucoslam/geometry/pose_information.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

void MapSession::AddBridgePrior(KeyframeId keyframe, double timestamp_s, bool world_aligned) {
  if (!options_.bridge_tracking_gaps || !closed_map_ || world_aligned) return;
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
  prior.information = IsotropicPoseInformation(position_sigma, rotation_sigma);
  bridge_priors_.push_back(prior);
  // For the bundle adjustments: how far a vehicle accelerating at most at the bound can
  // stray from the constant-velocity prediction over the gap.
  const double adjustment_sigma = options_.bridge_position_sigma_m +
                                  0.5 * options_.bridge_max_acceleration_m_s2 * gap_s * gap_s;
  prior.information.topLeftCorner<3, 3>() =
      IsotropicPoseInformation(adjustment_sigma, rotation_sigma).topLeftCorner<3, 3>();
  bridge_adjustment_priors_.push_back(prior);
  ARUCOSLAM_LOG_DEBUG(
      "keyframe {}: bridged over {:.2f} s from the closed map (sigma {:.2f} m, "
      "{:.2f} rad; {:.2f} m in bundle adjustment)",
      keyframe.value, gap_s, position_sigma, rotation_sigma, adjustment_sigma);
}

EssentialGraphResult MapSession::CorrectAcrossBridge(Map& map,
                                                     std::vector<KeyframePosePrior> marker_priors,
                                                     const EssentialGraphOptions& graph) {
  if (bridge_priors_.empty()) return {};
  std::vector<KeyframePosePrior> priors = std::move(marker_priors);
  priors.insert(priors.end(), bridge_priors_.begin(), bridge_priors_.end());
  bridge_priors_.clear();
  std::vector<KeyframePosePrior> adjustment_priors = std::move(bridge_adjustment_priors_);
  bridge_adjustment_priors_.clear();
  // The absorbed map is in the world already (adjusted with its markers when it was
  // closed): only the new map bends, between the bridge at its start and its markers.
  EssentialGraphResult result =
      OptimizeEssentialGraph(map, KeyframeId(), {}, {}, priors, graph, absorbed_keyframes_);
  ARUCOSLAM_LOG_DEBUG(
      "merged map corrected across the tracking gap over {} keyframes with {} "
      "priors, {} absorbed keyframes held: {}",
      result.num_keyframes, result.num_priors, absorbed_keyframes_.size(),
      result.summary.BriefReport());
  if (!result.applied) return result;
  if (options_.bridge_in_bundle_adjustment) {
    held_bridge_priors_.insert(held_bridge_priors_.end(), adjustment_priors.begin(),
                               adjustment_priors.end());
  }
  ++stats_.num_bridged_gaps;
  return result;
}

}  // namespace arucoslam
