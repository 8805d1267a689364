// System's drift correction by markers: when a keyframe of the world-aligned map has a marker
// location far from where the keypoints put it, the whole map is corrected by a Sim(3) pose
// graph (essential graph) with the marker location of every keyframe that had one as a prior.
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

KeyframePosePrior System::MarkerPrior(KeyframeId keyframe, const MarkerFix& fix) const {
  KeyframePosePrior prior;
  prior.keyframe = keyframe;
  prior.world_from_cam = fix.world_from_cam;
  prior.information = MarkerPriorInformation(
      options_.marker_priors, fix.nearest_marker_sides,
      static_cast<double>(std::max<std::size_t>(1, fix.markers.size())));
  return prior;
}

std::vector<KeyframePosePrior> System::KnownMarkerPriors() const {
  std::vector<KeyframePosePrior> priors;
  std::lock_guard lock(keyframe_fixes_mutex_);
  for (const auto& [id, fix] : keyframe_fixes_) {
    if (fix.known_markers_only) priors.push_back(MarkerPrior(id, fix));
  }
  return priors;
}

bool System::CorrectDriftWithMarkers(KeyframeId keyframe) {
  if (!options_.marker_drift_correction || !marker_mapping_live_) return false;
  std::optional<KeyframePosePrior> own;
  {
    std::lock_guard lock(keyframe_fixes_mutex_);
    // Mapped markers are estimates of this same map: only markers.json's anchor it.
    const auto found = keyframe_fixes_.find(keyframe);
    if (found == keyframe_fixes_.end() || !found->second.known_markers_only) return false;
    own = MarkerPrior(keyframe, found->second);
  }
  const std::vector<KeyframePosePrior> priors = KnownMarkerPriors();
  const std::optional<double> offset_m = map_->Read([&](const MapData& data) -> std::optional<double> {
    const Keyframe* found = data.FindKeyframe(keyframe);
    if (found == nullptr) return std::nullopt;
    return (own->world_from_cam.translation - found->cam_from_world.Inverse().translation).norm();
  });
  const double sigma_m = 1.0 / std::sqrt(own->information(0, 0));
  if (!offset_m || *offset_m < options_.min_marker_correction_m ||
      *offset_m < options_.marker_correction_sigmas * sigma_m) {
    return false;
  }
  if (places_) places_->MapMovedExternally();
  const EssentialGraphResult result = OptimizeEssentialGraph(
      *map_, KeyframeId(), {}, {}, priors, options_.marker_correction_graph);
  ARUCOSLAM_LOG_DEBUG("keyframe {}: {:.3f} m from its markers (sigma {:.3f} m), map corrected "
                      "over {} keyframes with {} marker priors: {}",
                      keyframe.value, *offset_m, sigma_m, result.num_keyframes, result.num_priors,
                      result.summary.BriefReport());
  if (!result.applied) return false;
  if (places_) places_->RecordScaleChanges(result.scale_changes);
  ++marker_corrections_;
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_marker_corrections;
  return true;
}

}  // namespace arucoslam
