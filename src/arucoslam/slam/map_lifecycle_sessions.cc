// MapLifecycle's map sessions (slam/map_session.h): a lost map reset or closed, merged into
// the next one, the gap bridged and the new map's initialisation backfilled.
#include <optional>
#include <utility>
#include <vector>

#include "arucoslam/slam/map_lifecycle.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

void MapLifecycle::MapInitialized(const MapLifecycleParts& parts, const InitialMap& initial,
                                  const Frame& second) {
  BackfillInitialization(parts, second, initial.first_id, initial.second_id);
  if (places_) {
    places_->KeyframeMapped(initial.first_id);
    places_->KeyframeMapped(initial.second_id);
  }
  session_.AddBridgePrior(initial.first_id, initial.first.timestamp_s, parts.anchoring.aligned());
}

bool MapLifecycle::OnLostFrame(const MapLifecycleParts& parts, const Frame& frame,
                               std::size_t frame_index) {
  LostMapState map;
  map.num_keyframes = parts.map.NumKeyframes();
  map.world_aligned = parts.anchoring.aligned();
  map.frame_has_marker_fix = parts.marker_fusion.fix().has_value();
  map.loaded = map_loaded_;
  const LossAction action = session_.OnLostFrame(frame, map);
  if (action == LossAction::kKeep) return false;
  if (action == LossAction::kNewMap) {
    ARUCOSLAM_LOG_DEBUG("frame {}: lost for {:.1f} s, starting a new map", frame_index,
                        session_.options().new_map_after_lost_s);
  }
  return true;
}

bool MapLifecycle::CloseMap(const MapLifecycleParts& parts) {
  bool kept_for_merge = false;
  const std::size_t keyframes = parts.map.NumKeyframes();
  switch (session_.DecideClosing(keyframes, parts.anchoring.aligned())) {
    case MapClosing::kNothing:
    case MapClosing::kDiscarded:  // not in the world frame: its poses are dropped below
      break;
    case MapClosing::kBiggestKeypointMap:
      session_.KeepBiggestKeypointMap(
          parts.pose_history.CurrentMapPoses(parts.map, /*world_only=*/false), keyframes);
      break;
    case MapClosing::kInWorld: {
      // Before its poses are frozen: the whole map against every marker it saw.
      AdjustWholeMapWithMarkers(parts.map, parts.marker_mapping, "map closed");
      const bool aligned = parts.anchoring.aligned();
      ClosingWorldMap closing;
      // Frames off their keyframes (a plain wall before the loss) would bend the bridge's
      // velocity.
      closing.motion_poses = DropPosesOffTheirKeyframes(
          parts.pose_history.CurrentMapPoses(parts.map, /*world_only=*/true),
          KeyframePoses(parts.map, aligned), pose_consistency_);
      closing.keyframes = KeyframePoses(parts.map, aligned);
      closing.points = MapPoints(parts.map, aligned);
      closing.keyframe_fixes = parts.anchoring.KeyframeFixes();
      kept_for_merge = session_.CloseWorldMap(parts.map, std::move(closing));
      break;
    }
  }
  // Poses already in the world frame stay, frozen at their current estimate.
  parts.pose_history.FreezeForReset(parts.map, kept_for_merge);
  places_.reset();
  return kept_for_merge;
}

void MapLifecycle::StartNewMap(const MapLifecycleParts& parts, bool kept_for_merge) {
  MakePlaces(parts);
  const int marker_generation = parts.marker_mapping.CloseMap();
  session_.StartNewMap(kept_for_merge ? std::optional<int>(marker_generation) : std::nullopt);
  // None: the new places hold none yet, the marker mapper drops them.
  HandOutBridgePriors(parts.marker_mapping);
}

bool MapLifecycle::MergeClosedMap(const MapLifecycleParts& parts) {
  const std::optional<MergedClosedMap> merged = session_.MergeClosedMap(parts.map);
  if (!merged) return false;
  const AbsorbedIds& ids = merged->ids;
  // Its frozen poses follow their keyframes again.
  const int followed = parts.pose_history.FollowMergedMap(parts.map, ids);
  parts.anchoring.AddKeyframeFixes(merged->keyframe_fixes);
  const int revived =
      parts.marker_mapping.ReviveClosedMap(merged->marker_generation, ids.keyframes);
  if (places_) {
    std::vector<KeyframeId> absorbed;
    for (const auto& [old_id, id] : ids.keyframes) absorbed.push_back(id);
    places_->IndexKeyframes(absorbed);
  }
  ARUCOSLAM_LOG_DEBUG(
      "closed map merged into the current one: {} keyframes, {} points, {} "
      "poses follow them, {} with marker views; attached to keyframe {}",
      ids.keyframes.size(), ids.points.size(), followed, revived, merged->attached_to.value);
  CorrectAcrossBridge(parts);
  return true;
}

void MapLifecycle::CorrectAcrossBridge(const MapLifecycleParts& parts) {
  if (!session_.HasBridgePriors()) return;
  std::vector<KeyframePosePrior> marker_priors = parts.anchoring.KnownMarkerPriors();
  if (places_) places_->MapMovedExternally();
  const EssentialGraphResult result =
      session_.CorrectAcrossBridge(parts.map, std::move(marker_priors), correction_graph_);
  if (!result.applied) return;
  HandOutBridgePriors(parts.marker_mapping);
  if (places_) places_->RecordScaleChanges(result.scale_changes);
}

void MapLifecycle::HandOutBridgePriors(OnlineMarkerMapping& marker_mapping) {
  const std::vector<KeyframePosePrior>& priors = session_.held_bridge_priors();
  marker_mapping.SetPositionPriors(priors);
  if (places_) places_->SetBundleAdjustmentPriors(priors);
}

void MapLifecycle::BackfillInitialization(const MapLifecycleParts& parts, const Frame& second,
                                          KeyframeId first_id, KeyframeId second_id) {
  const std::vector<Frame> tracked =
      session_.TrackBackfill(parts.map, tracker_options_, second, first_id, second_id);
  if (tracked.empty()) return;
  // Marker-only poses of the same frames give way to the keypoint ones.
  const int num_replaced = parts.pose_history.MergeBackfill(
      parts.map, tracked, first_id, parts.anchoring.aligned(), parts.marker_fusion.fix());
  // Newly with a pose.
  AddToStats(stats_, stats_mutex_, &FrameFlowStats::num_tracked,
             static_cast<int>(tracked.size()) - num_replaced);
}

}  // namespace arucoslam
