// System's marker mapping wiring: once the keypoint map is in the marker world, marker_mapping_
// (slam/online_marker_mapping.h) records every keyframe's markers and its landmarks join local
// and loop bundle adjustment; its whole-map adjustments and drift corrections run here under
// the places' locks.
#include <optional>
#include <vector>

#include "arucoslam/pipeline/system.h"

namespace arucoslam {

void System::StartMarkerMapping() {
  if (!marker_mapping_.Start()) return;
  if (MarkerLandmarks* landmarks = marker_mapping_.landmarks_for_bundle_adjustment()) {
    mapper_->SetMarkerLandmarks(landmarks);
    // The caller holds the places' edit lock (LockPlacesForMapMove).
    if (places_) places_->SetMarkerLandmarks(landmarks);
  }
  if (places_ && options_.world_anchoring.priors_in_loops) {
    places_->SetLoopPosePriors([this] { return anchoring_.KnownMarkerPriors(); },
                               options_.world_anchoring.marker_correction_graph);
  }
  // Keyframes mapped before the alignment are recorded now, at their aligned poses.
  for (const KeyframeId& id : marker_mapping_.UnfedKeyframes(*map_)) {
    marker_mapping_.AddKeyframe(*map_, id);
  }
}

void System::AdjustWholeMapWithMarkers(const char* when) {
  if (!marker_mapping_.AdjustsWholeMap()) return;
  // A global BA of the loop closer may be solving: it is discarded, and the landmarks it
  // writes under this lock are not touched meanwhile.
  const std::unique_lock<std::mutex> places_lock = LockPlacesForMapMove();
  marker_mapping_.AdjustWholeMap(map_.get(), when);
}

bool System::CorrectDriftWithMarkers(KeyframeId keyframe) {
  const std::optional<DriftCorrectionDecision> decision =
      marker_mapping_.DecideDriftCorrection(*map_, anchoring_, keyframe);
  if (!decision) return false;
  if (places_) places_->MapMovedExternally();
  const EssentialGraphResult result = marker_mapping_.CorrectDrift(
      map_.get(), keyframe, *decision, options_.world_anchoring.marker_correction_graph);
  if (!result.applied) return false;
  if (places_) places_->RecordScaleChanges(result.scale_changes);
  anchoring_.DriftCorrected();
  return true;
}

MarkerMap System::MarkerMapOutput() const { return marker_mapping_.ToMarkerMap(); }

}  // namespace arucoslam
