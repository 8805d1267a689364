// FrameFlow's maps: starting from a saved map and relocalising into it, the place database's
// relocalisation and loop corrections, and the map sessions (slam/map_session.h): a lost map
// reset or closed, merged into the next one, the gap bridged and the initialisation backfilled.
#include <optional>
#include <utility>
#include <vector>

#include "arucoslam/slam/frame_flow.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

void FrameFlow::StartFromMap(MapData map, bool world_aligned, bool localize_only) {
  map_->Write([&map](MapData& data) { data = std::move(map); });
  map_loaded_ = true;
  localize_only_ = localize_only;
  anchoring_.StartLoadedMap(world_aligned);
  if (places_) {
    places_->SetMetricMap(world_aligned);
    places_->IndexExistingKeyframes();
  }
}

void FrameFlow::LocalizeInLoadedMap(Frame& frame, FrameReport& report) {
  report.state = TrackingState::kNotInitialized;
  if (!RelocalizeWithMarkers(frame, report) && !RelocalizeWithPlaces(frame, report) &&
      !RelocalizeInLoadedMap(frame, report)) {
    report.message = "not localised in the loaded map";
    return;
  }
  last_state_ = TrackingState::kTracking;
  frames_since_keyframe_ = 0;
  report.state = TrackingState::kTracking;
  report.cam_from_world = frame.cam_from_world;
  RecordPose(frame, tracker_->reference_keyframe());
}

bool FrameFlow::RelocalizeInLoadedMap(Frame& frame, FrameReport& report) {
  // Brute-force keyframe matching, for a loaded map without a place database only.
  if (!map_loaded_ || places_) return false;
  const std::optional<int> num_inliers =
      loaded_map_relocalizer_.Relocalize(*map_, *tracker_, frame, report.index);
  if (!num_inliers) return false;
  report.num_inliers = *num_inliers;
  report.message = "relocalised in the loaded map";
  CountStat(&FrameFlowStats::num_map_relocalizations);
  return true;
}

void FrameFlow::MakePlaces() {
  places_.reset();
  seen_corrections_ = 0;
  pose_history_.ForgetKeyframePoses();
  places_ = make_places_(*map_);
}

bool FrameFlow::RelocalizeWithPlaces(Frame& frame, FrameReport& report) {
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
  places_->RelocalizationTaken();
  return true;
}

void FrameFlow::RefreshKeyframePoseCache() {
  if (places_) pose_history_.RememberKeyframePoses(*map_);
}

void FrameFlow::FollowMapCorrections() {
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

std::unique_lock<std::mutex> FrameFlow::LockPlacesForMapMove() {
  if (!places_) return {};
  std::unique_lock<std::mutex> lock = places_->LockMapEdits();
  places_->MapMovedExternally();
  // The only outside move is the alignment to the marker world, which makes the map metric.
  places_->SetMetricMap(true);
  return lock;
}

void FrameFlow::HandleLostFrame(const Frame& frame, std::size_t frame_index) {
  LostMapState map;
  map.num_keyframes = map_->NumKeyframes();
  map.world_aligned = anchoring_.aligned();
  map.frame_has_marker_fix = marker_fusion_.fix().has_value();
  map.loaded = map_loaded_;
  const LossAction action = map_session_.OnLostFrame(frame, map);
  if (action == LossAction::kKeep) return;
  if (action == LossAction::kNewMap) {
    ARUCOSLAM_LOG_DEBUG("frame {}: lost for {:.1f} s, starting a new map", frame_index,
                        options_.map_session.new_map_after_lost_s);
  }
  ResetMap();
}

void FrameFlow::ResetMap() {
  mapping_->Pause();
  const bool kept_for_merge = CloseMap();
  // Poses already in the world frame stay, frozen at their current estimate.
  pose_history_.FreezeForReset(*map_, kept_for_merge);
  places_.reset();
  tracker_.reset();
  mapper_.reset();
  map_ = std::make_unique<Map>();
  tracker_ = std::make_unique<Tracker>(*map_, options_.tracker);
  MakeLocalMapper();
  MakePlaces();
  const int marker_generation = marker_mapping_.CloseMap();
  map_session_.StartNewMap(kept_for_merge ? std::optional<int>(marker_generation) : std::nullopt);
  HandOutBridgePriors();  // none: the new places hold none yet, the marker mapper drops them
  map_initializer_.Reset();
  anchoring_.Reset();
  marker_fusion_.MapReset();
  last_state_ = TrackingState::kNotInitialized;
  mapping_->Resume();
}

bool FrameFlow::CloseMap() {
  const std::size_t keyframes = map_->NumKeyframes();
  switch (map_session_.DecideClosing(keyframes, anchoring_.aligned())) {
    case MapClosing::kNothing:
    case MapClosing::kDiscarded:  // not in the world frame: ResetMap drops its poses
      return false;
    case MapClosing::kBiggestKeypointMap:
      map_session_.KeepBiggestKeypointMap(
          pose_history_.CurrentMapPoses(*map_, /*world_only=*/false), keyframes);
      return false;
    case MapClosing::kInWorld:
      break;
  }
  // Before its poses are frozen: the whole map against every marker it saw.
  AdjustWholeMapWithMarkers("map closed");
  ClosingWorldMap closing;
  // Frames off their keyframes (a plain wall before the loss) would bend the bridge's velocity.
  closing.motion_poses =
      DropPosesOffTheirKeyframes(pose_history_.CurrentMapPoses(*map_, /*world_only=*/true),
                                 KeyframePoses(), options_.pose_consistency);
  closing.keyframes = KeyframePoses();
  closing.points = MapPoints();
  closing.keyframe_fixes = anchoring_.KeyframeFixes();
  return map_session_.CloseWorldMap(*map_, std::move(closing));
}

bool FrameFlow::MergeClosedMap() {
  const std::optional<MergedClosedMap> merged = map_session_.MergeClosedMap(*map_);
  if (!merged) return false;
  const AbsorbedIds& ids = merged->ids;
  // Its frozen poses follow their keyframes again.
  const int followed = pose_history_.FollowMergedMap(*map_, ids);
  anchoring_.AddKeyframeFixes(merged->keyframe_fixes);
  const int revived = marker_mapping_.ReviveClosedMap(merged->marker_generation, ids.keyframes);
  if (places_) {
    std::vector<KeyframeId> absorbed;
    for (const auto& [old_id, id] : ids.keyframes) absorbed.push_back(id);
    places_->IndexKeyframes(absorbed);
  }
  ARUCOSLAM_LOG_DEBUG(
      "closed map merged into the current one: {} keyframes, {} points, {} "
      "poses follow them, {} with marker views; attached to keyframe {}",
      ids.keyframes.size(), ids.points.size(), followed, revived, merged->attached_to.value);
  return true;
}

void FrameFlow::CorrectAcrossBridge() {
  if (!map_session_.HasBridgePriors()) return;
  std::vector<KeyframePosePrior> marker_priors = anchoring_.KnownMarkerPriors();
  if (places_) places_->MapMovedExternally();
  const EssentialGraphResult result = map_session_.CorrectAcrossBridge(
      *map_, std::move(marker_priors), options_.world_anchoring.marker_correction_graph);
  if (!result.applied) return;
  HandOutBridgePriors();
  if (places_) places_->RecordScaleChanges(result.scale_changes);
}

void FrameFlow::HandOutBridgePriors() {
  const std::vector<KeyframePosePrior>& priors = map_session_.held_bridge_priors();
  marker_mapping_.SetPositionPriors(priors);
  if (places_) places_->SetBundleAdjustmentPriors(priors);
}

void FrameFlow::BackfillInitialization(const Frame& second, KeyframeId first_id,
                                       KeyframeId second_id) {
  const std::vector<Frame> tracked =
      map_session_.TrackBackfill(*map_, options_.tracker, second, first_id, second_id);
  if (tracked.empty()) return;
  // Marker-only poses of the same frames give way to the keypoint ones.
  const int num_replaced = pose_history_.MergeBackfill(*map_, tracked, first_id,
                                                       anchoring_.aligned(), marker_fusion_.fix());
  // Newly with a pose.
  CountStat(&FrameFlowStats::num_tracked, static_cast<int>(tracked.size()) - num_replaced);
}

}  // namespace arucoslam
