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
  // Poses already in the world frame stay, frozen at their current estimate (those of a map
  // kept for a merge remember their keyframe there).
  std::vector<TrackedPose> kept;
  map_->Read([&](const MapData& data) {
    for (TrackedPose pose : poses_) {
      if (!pose.in_world && pose.marker_cam_from_world) {  // frozen at its marker location
        pose.cam_from_world = *pose.marker_cam_from_world;
        pose.cam_from_reference = pose.cam_from_world;
        pose.reference = KeyframeId();
        pose.in_world = true;
      }
      if (!pose.in_world) continue;
      if (kept_for_merge) pose.closed_reference = KeyframeId();  // an older closed map's
      if (const Keyframe* reference = data.FindKeyframe(pose.reference)) {
        pose.cam_from_world = PoseFromReference(pose, reference->cam_from_world);
        if (kept_for_merge) pose.closed_reference = pose.reference;
      }
      pose.reference = KeyframeId();
      if (!pose.closed_reference.IsValid()) {  // frozen for good: never refined
        pose.matches = {};
        pose.markers = {};
      }
      kept.push_back(std::move(pose));
    }
    return 0;
  });
  places_.reset();
  tracker_.reset();
  mapper_.reset();
  map_ = std::make_unique<Map>();
  tracker_ = std::make_unique<Tracker>(*map_, options_.tracker);
  MakeLocalMapper();
  MakePlaceRecognition();
  const int marker_generation = ResetMarkerMapping();
  map_session_.StartNewMap(kept_for_merge ? std::optional<int>(marker_generation) : std::nullopt);
  HandOutBridgePriors();  // none: the new places hold none yet, the marker mapper drops them
  poses_ = std::move(kept);
  init_reference_.reset();
  init_reference_fix_.reset();
  anchoring_.Reset();
  marker_fusion_.MapReset();
  last_state_ = TrackingState::kNotInitialized;
  StartMappingThread();
}

bool System::CloseMap() {
  const std::size_t keyframes = map_->NumKeyframes();
  switch (map_session_.DecideClosing(keyframes, anchoring_.aligned())) {
    case MapClosing::kNothing:
    case MapClosing::kDiscarded:  // not in the world frame: ResetMap drops its poses
      return false;
    case MapClosing::kBiggestKeypointMap:
      map_session_.KeepBiggestKeypointMap(CurrentMapPoses(/*world_only=*/false), keyframes);
      return false;
    case MapClosing::kInWorld:
      break;
  }
  // Before its poses are frozen: the whole map against every marker it saw.
  AdjustWholeMapWithMarkers("map closed");
  ClosingWorldMap closing;
  // Frames off their keyframes (a plain wall before the loss) would bend the bridge's velocity.
  closing.motion_poses = DropPosesOffTheirKeyframes(CurrentMapPoses(/*world_only=*/true),
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
  int followed = 0;
  map_->Read([&](const MapData& data) {
    for (TrackedPose& pose : poses_) {
      if (!pose.closed_reference.IsValid()) continue;
      const auto found = ids.keyframes.find(pose.closed_reference);
      pose.closed_reference = KeyframeId();
      if (found == ids.keyframes.end()) continue;
      pose.reference = found->second;
      std::vector<FrameMatch> matches;  // its points have new ids here
      for (const FrameMatch& match : pose.matches) {
        const auto point = ids.points.find(match.point);
        if (point != ids.points.end())
          matches.push_back({point->second, match.pixel, match.sigma_px});
      }
      pose.matches = std::move(matches);
      pose.cam_from_reference =
          pose.cam_from_world * data.FindKeyframe(found->second)->cam_from_world.Inverse();
      pose.reference_scale = ReferenceScale(found->second);
      ++followed;
    }
    return 0;
  });
  anchoring_.AddKeyframeFixes(merged->keyframe_fixes);
  int revived = 0;
  if (marker_mapper_ && merged->marker_generation >= 0) {
    revived = marker_mapper_->ReviveClosedMap(merged->marker_generation, ids.keyframes);
  }
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
  if (marker_mapper_) marker_mapper_->SetPositionPriors(priors);
  if (places_) places_->SetBundleAdjustmentPriors(priors);
}

void System::ReplaceInitReference(const Frame& frame) {
  if (init_reference_) map_session_.KeepForBackfill(*init_reference_);
  init_reference_ = frame;
  init_reference_fix_ = marker_fusion_.fix();
}

void System::BackfillInitialization(const Frame& second, KeyframeId first_id,
                                    KeyframeId second_id) {
  const std::vector<Frame> tracked =
      map_session_.TrackBackfill(*map_, options_.tracker, second, first_id, second_id);
  if (tracked.empty()) return;
  // Marker-only poses of the same frames give way to the keypoint ones; time order is kept.
  std::vector<TrackedPose> merged;
  merged.reserve(poses_.size() + tracked.size());
  int num_replaced = 0;
  for (TrackedPose& pose : poses_) {
    const bool replaced = std::any_of(tracked.begin(), tracked.end(), [&](const Frame& frame) {
      return frame.timestamp_s == pose.timestamp_s;
    });
    if (replaced) {
      ++num_replaced;
    } else {
      merged.push_back(std::move(pose));
    }
  }
  for (const Frame& frame : tracked) merged.push_back(MakeTrackedPose(frame, first_id));
  std::stable_sort(merged.begin(), merged.end(), [](const TrackedPose& a, const TrackedPose& b) {
    return a.timestamp_s < b.timestamp_s;
  });
  poses_ = std::move(merged);
  std::lock_guard lock(stats_mutex_);
  stats_.num_tracked += static_cast<int>(tracked.size()) - num_replaced;  // newly with a pose
}

}  // namespace arucoslam
