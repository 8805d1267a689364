// System's side of the map sessions (slam/map_session.h): a lost map reset or replaced, the
// closed map merged into the current one with its poses, marker views and place entries, the
// bridge priors handed to the adjustments, and the backfilled frames' poses recorded.
#include <algorithm>
#include <utility>
#include <vector>

#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

void System::HandleLostFrame(const Frame& frame, std::size_t frame_index) {
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

void System::ResetMap() {
  StopMappingThread();
  const bool kept_for_merge = CloseMap();
  // Poses already in the world frame stay, frozen at their current estimate.
  pose_history_.FreezeForReset(*map_, kept_for_merge);
  places_.reset();
  tracker_.reset();
  mapper_.reset();
  map_ = std::make_unique<Map>();
  tracker_ = std::make_unique<Tracker>(*map_, options_.tracker);
  MakeLocalMapper();
  MakePlaceRecognition();
  const int marker_generation = marker_mapping_.CloseMap();
  map_session_.StartNewMap(kept_for_merge ? std::optional<int>(marker_generation) : std::nullopt);
  HandOutBridgePriors();  // none: the new places hold none yet, the marker mapper drops them
  map_initializer_.Reset();
  anchoring_.Reset();
  marker_fusion_.MapReset();
  last_state_ = TrackingState::kNotInitialized;
  mapping_busy_ = false;
  StartMappingThread();
}

bool System::CloseMap() {
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

bool System::MergeClosedMap() {
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

void System::CorrectAcrossBridge() {
  if (!map_session_.HasBridgePriors()) return;
  std::vector<KeyframePosePrior> marker_priors = anchoring_.KnownMarkerPriors();
  if (places_) places_->MapMovedExternally();
  const EssentialGraphResult result = map_session_.CorrectAcrossBridge(
      *map_, std::move(marker_priors), options_.world_anchoring.marker_correction_graph);
  if (!result.applied) return;
  HandOutBridgePriors();
  if (places_) places_->RecordScaleChanges(result.scale_changes);
}

void System::HandOutBridgePriors() {
  const std::vector<KeyframePosePrior>& priors = map_session_.held_bridge_priors();
  marker_mapping_.SetPositionPriors(priors);
  if (places_) places_->SetBundleAdjustmentPriors(priors);
}

void System::BackfillInitialization(const Frame& second, KeyframeId first_id,
                                    KeyframeId second_id) {
  const std::vector<Frame> tracked =
      map_session_.TrackBackfill(*map_, options_.tracker, second, first_id, second_id);
  if (tracked.empty()) return;
  // Marker-only poses of the same frames give way to the keypoint ones.
  const int num_replaced = pose_history_.MergeBackfill(*map_, tracked, first_id,
                                                       anchoring_.aligned(), marker_fusion_.fix());
  std::lock_guard lock(stats_mutex_);
  stats_.num_tracked += static_cast<int>(tracked.size()) - num_replaced;  // newly with a pose
}

}  // namespace arucoslam
