// System's place recognition: one PlaceRecognition per map (keyframe database, loop
// closing, global BA), relocalisation of lost frames, and following loop corrections.
#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

void System::MakePlaceRecognition() {
  places_.reset();
  seen_corrections_ = 0;
  pose_history_.ForgetKeyframePoses();
  if (!options_.vocabulary) return;
  places_ = std::make_unique<PlaceRecognition>(*map_, options_.vocabulary, options_.places,
                                               !options_.blocking, &stats_.places, &stats_mutex_);
}

bool System::RelocalizeWithPlaces(Frame& frame, FrameReport& report) {
  if (!places_) return false;
  const std::optional<RelocalizationResult> found = places_->Relocalize(frame);
  if (!found) return false;
  // Look-alike places: in a map aligned to the marker world only a pose that the frame's
  // markers confirm is taken.
  if (options_.marker_map && anchoring_.aligned() &&
      !marker_fusion_.Confirms(found->cam_from_world)) {
    ARUCOSLAM_LOG_DEBUG("frame {}: place relocalisation not confirmed by markers", report.index);
    return false;
  }
  // The database pose is refined against the local map as after a marker relocalisation.
  const TrackingResult result = tracker_->TrackFromPose(frame, found->cam_from_world);
  if (result.state != TrackingState::kTracking) return false;
  tracker_->SetReferenceKeyframe(found->keyframe);
  report.num_inliers = result.num_inliers;
  report.message = "relocalised from the place database";
  ARUCOSLAM_LOG_DEBUG("frame {}: relocalised from keyframe {}, {} inliers", report.index,
                      found->keyframe.value, result.num_inliers);
  std::lock_guard lock(stats_mutex_);
  ++stats_.places.num_relocalizations;
  return true;
}

void System::RefreshKeyframePoseCache() {
  if (places_) pose_history_.RememberKeyframePoses(*map_);
}

void System::FollowMapCorrections() {
  if (places_) pose_history_.ReanchorOrphans(*map_);
  const bool places_moved = places_ && places_->corrections() != seen_corrections_;
  const int marker_corrections = anchoring_.stats().num_drift_corrections;
  const bool markers_moved = marker_corrections != seen_marker_corrections_;
  if (!places_moved && !markers_moved) return;
  if (places_) seen_corrections_ = places_->corrections();
  seen_marker_corrections_ = marker_corrections;
  if (tracker_->state() != TrackingState::kTracking) return;
  if (const std::optional<Sim3> correction = pose_history_.LastPoseCorrection(*map_)) {
    tracker_->ApplySimilarity(*correction);
  }
}

std::unique_lock<std::mutex> System::LockPlacesForMapMove() {
  if (!places_) return {};
  std::unique_lock<std::mutex> lock = places_->LockMapEdits();
  places_->MapMovedExternally();
  // The only outside move is the alignment to the marker world, which makes the map metric.
  places_->SetMetricMap(true);
  return lock;
}

}  // namespace arucoslam
