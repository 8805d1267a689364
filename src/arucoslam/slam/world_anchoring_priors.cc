// WorldAnchoring's marker priors and the decision to correct drift with them.
#include <algorithm>
#include <cmath>

#include "arucoslam/slam/world_anchoring.h"

namespace arucoslam {

KeyframePosePrior WorldAnchoring::MarkerPrior(KeyframeId keyframe, const MarkerFix& fix) const {
  KeyframePosePrior prior;
  prior.keyframe = keyframe;
  prior.world_from_cam = fix.world_from_cam;
  prior.information =
      MarkerPriorInformation(options_.marker_priors, fix.nearest_marker_sides,
                             static_cast<double>(std::max<std::size_t>(1, fix.markers.size())));
  return prior;
}

std::vector<KeyframePosePrior> WorldAnchoring::KnownMarkerPriors() const {
  std::vector<KeyframePosePrior> priors;
  std::lock_guard lock(fixes_mutex_);
  for (const auto& [id, fix] : keyframe_fixes_) {
    if (fix.known_markers_only) priors.push_back(MarkerPrior(id, fix));
  }
  return priors;
}

std::optional<DriftCorrectionDecision> WorldAnchoring::DecideDriftCorrection(
    const Map& map, KeyframeId keyframe) const {
  if (!options_.drift_correction) return std::nullopt;
  std::optional<KeyframePosePrior> own;
  {
    std::lock_guard lock(fixes_mutex_);
    // Mapped markers are estimates of this same map: only markers.json's anchor it.
    const auto found = keyframe_fixes_.find(keyframe);
    if (found == keyframe_fixes_.end() || !found->second.known_markers_only) return std::nullopt;
    own = MarkerPrior(keyframe, found->second);
  }
  DriftCorrectionDecision decision;
  decision.priors = KnownMarkerPriors();
  const std::optional<double> offset_m = map.Read([&](const MapData& data)
                                                      -> std::optional<double> {
    const Keyframe* found = data.FindKeyframe(keyframe);
    if (found == nullptr) return std::nullopt;
    return (own->world_from_cam.translation - found->cam_from_world.Inverse().translation).norm();
  });
  decision.sigma_m = 1.0 / std::sqrt(own->information(0, 0));
  if (!offset_m || *offset_m < options_.min_marker_correction_m ||
      *offset_m < options_.marker_correction_sigmas * decision.sigma_m) {
    return std::nullopt;
  }
  decision.offset_m = *offset_m;
  return decision;
}

}  // namespace arucoslam
