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

bool System::CorrectDriftWithMarkers(KeyframeId keyframe) {
  if (!marker_mapping_live_) return false;
  const std::optional<DriftCorrectionDecision> decision =
      anchoring_.DecideDriftCorrection(*map_, keyframe);
  if (!decision) return false;
  if (places_) places_->MapMovedExternally();
  const EssentialGraphResult result =
      OptimizeEssentialGraph(*map_, KeyframeId(), {}, {}, decision->priors,
                             options_.world_anchoring.marker_correction_graph);
  ARUCOSLAM_LOG_DEBUG("keyframe {}: {:.3f} m from its markers (sigma {:.3f} m), map corrected "
                      "over {} keyframes with {} marker priors: {}",
                      keyframe.value, decision->offset_m, decision->sigma_m, result.num_keyframes,
                      result.num_priors, result.summary.BriefReport());
  if (!result.applied) return false;
  if (places_) places_->RecordScaleChanges(result.scale_changes);
  anchoring_.DriftCorrected();
  return true;
}

}  // namespace arucoslam
