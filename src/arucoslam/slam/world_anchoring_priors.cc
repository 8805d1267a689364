// WorldAnchoring's marker priors and the decision to correct drift with them.
#include <algorithm>
#include <cmath>

#include "arucoslam/optim/pose_graph.h"
#include "arucoslam/slam/world_anchoring.h"

namespace arucoslam {

KeyframePosePrior WorldAnchoring::MarkerPrior(KeyframeId keyframe, const MarkerFix& fix) const {
  KeyframePosePrior prior;
  prior.keyframe = keyframe;
  prior.world_from_cam = fix.world_from_cam;
  prior.information = MarkerPriorInformation(
      options_.marker_priors, static_cast<double>(std::max<std::size_t>(1, fix.markers.size())),
      fix.corner_information);
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
  const std::optional<Rigid3> keypoint_cam_from_world =
      map.Read([&](const MapData& data) -> std::optional<Rigid3> {
        const Keyframe* found = data.FindKeyframe(keyframe);
        if (found == nullptr) return std::nullopt;
        return found->cam_from_world;
      });
  if (!keypoint_cam_from_world) return std::nullopt;
  DriftCorrectionDecision decision;
  decision.offset_m =
      (keypoint_cam_from_world->Inverse().translation - own->world_from_cam.translation).norm();
  // The keypoint pose's error as the pose graph measures the marker prior.
  PoseGraphProblem keyframe_alone;
  keyframe_alone.nodes.push_back({Sim3(*keypoint_cam_from_world)});
  keyframe_alone.priors.push_back({0, own->world_from_cam, own->information});
  decision.offset_sigmas = std::sqrt(std::max(0.0, PoseGraphChiSquare(keyframe_alone)));
  if (decision.offset_m < options_.min_marker_correction_m ||
      decision.offset_sigmas < options_.marker_correction_sigmas) {
    return std::nullopt;
  }
  decision.priors = KnownMarkerPriors();
  return decision;
}

}  // namespace arucoslam
