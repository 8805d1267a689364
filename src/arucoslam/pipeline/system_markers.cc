// System's marker handling: each frame's markers handed to the marker fusion, marker-only
// poses, relocalisation from a marker pose, and the Sim(3) alignment of the keypoint map to
// the world.
#include <optional>
#include <set>
#include <vector>

#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {
void System::LocateWithMarkers(Frame& frame, const std::vector<MarkerDetection>& detections,
                               FrameReport& report) {
  if (!options_.marker_map) return;
  const Stopwatch watch;
  if (options_.marker_map->markers.empty() && !detections.empty() && !marker_mapping_live_ &&
      EnsureMarkerMapper().AdoptWorldOrigin(detections, frame.camera)) {
    PublishLocatingMarkers();
  }
  frame.markers.clear();
  for (const MarkerDetection& detection : detections) {
    frame.markers.push_back({MarkerId(detection.id), detection.corners});
  }
  const std::shared_ptr<const MarkerMap> locating = LocatingMarkers();
  MapPrediction prediction;
  prediction.world_aligned = anchoring_.aligned();
  prediction.tracking = tracker_->state() == TrackingState::kTracking;
  prediction.predicted_cam_from_map = tracker_->PredictedPose();
  marker_fusion_.Locate(detections, locating ? *locating : *options_.marker_map, frame.timestamp_s,
                        prediction, report.index);
  report.num_markers = marker_fusion_.num_markers();
  std::lock_guard lock(stats_mutex_);
  const double locating_ms = watch.ElapsedMilliseconds();
  stats_.marker_ms.Add(detection_ms_ + locating_ms);
  stats_.marker_wait_ms.Add(marker_wait_ms_ + locating_ms);
  detection_ms_ = marker_wait_ms_ = 0.0;
}

void System::GuardMarkerKeyframes() {
  if (!options_.marker_map) return;
  mapper_->SetKeyframeGuard(
      [this](const Keyframe& keyframe) { return anchoring_.KeepsKeyframe(keyframe); });
}

bool System::RelocalizeWithMarkers(Frame& frame, FrameReport& report) {
  const std::optional<MarkerFix>& fix = marker_fusion_.fix();
  if (!anchoring_.aligned() || !fix) return false;
  const TrackingResult result =
      tracker_->TrackFromPose(frame, fix->world_from_cam.Inverse(), fix->markers);
  if (result.state != TrackingState::kTracking) return false;
  report.num_inliers = result.num_inliers;
  report.message = "relocalised from markers";
  ARUCOSLAM_LOG_DEBUG("frame {}: relocalised from markers, {} inliers", report.index,
                      result.num_inliers);
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_marker_relocalizations;
  return true;
}

void System::MaybeAlignWorld(Frame& frame) {
  const std::optional<AlignmentDecision> decision = anchoring_.DecideAlignment(*map_);
  if (!decision) return;
  const std::vector<WorldAnchor>& anchors = decision->anchors;
  const WorldAlignment& alignment = decision->alignment;
  const Sim3& world_from_map = alignment.world_from_map;
  StopMappingThread();  // every queued keyframe is mapped first; mapping is idle below
  const std::set<KeyframeId>& absorbed = map_session_.absorbed_keyframes();
  if (anchoring_.aligned() && !absorbed.empty() && map_session_.LinkedToAbsorbedMap(*map_)) {
    // A merged map that shares points with this one now (a loop, fused points): a
    // re-alignment from this map's anchors alone would tear them apart. Markers correct the
    // map by fusion from here on (drift correction, marker corners in bundle adjustment).
    anchoring_.StopRealigning();
    StartMappingThread();
    ARUCOSLAM_LOG_DEBUG("world re-alignment stopped: the merged map is linked to this one");
    return;
  }
  anchoring_.DropOutlierFixes(*decision);
  // A merged map not linked yet stays where it is (already in the world).
  const std::set<KeyframeId>* stay = absorbed.empty() ? nullptr : &absorbed;
  const std::unique_lock<std::mutex> places_lock = LockPlacesForMapMove();
  // On a re-alignment the markers mapped in the previous estimate of the world move too.
  MarkerLandmarks* mapped =
      marker_mapping_live_ ? marker_mapper_->mutable_landmarks() : nullptr;
  map_->Write([&](MapData& data) { ApplyWorldAlignment(world_from_map, &data, mapped, stay); });
  if (mapped != nullptr) marker_mapper_->ApplySimilarity(world_from_map, stay);
  StartMarkerMapping();
  tracker_->ApplySimilarity(world_from_map);
  const auto to_world = [&](const Rigid3& cam_from_map) {
    return world_from_map.TransformPose(cam_from_map.Inverse()).Inverse();
  };
  for (TrackedPose& pose : poses_) {
    // Marker-only and frozen poses (no reference) are in the world already; on a
    // re-alignment the poses tied to this map's keyframes move with them.
    const bool moves = !pose.in_world || (anchoring_.aligned() && pose.reference.IsValid() &&
                                           absorbed.count(pose.reference) == 0);
    if (!moves) continue;
    pose.cam_from_world = to_world(pose.cam_from_world);
    pose.cam_from_reference.translation *= world_from_map.scale;
    pose.in_world = true;
  }
  if (frame.cam_from_world) frame.cam_from_world = to_world(*frame.cam_from_world);
  if (MergeClosedMap()) CorrectAcrossBridge();
  StartMappingThread();
  ARUCOSLAM_LOG_DEBUG("keypoint map {}aligned to the marker world: scale {:.4f}, {} of {} "
                      "anchors, rms {:.3f} m",
                      anchoring_.aligned() ? "re-" : "", world_from_map.scale,
                      alignment.num_inliers, anchors.size(), alignment.rms_m);
  anchoring_.AlignmentApplied(*decision);
  marker_fusion_.MapEnteredWorld(frame.timestamp_s);  // the anchors agree with the map
  RefreshKeyframePoseCache();
}

void System::RecordMarkerPose(const Frame& frame, FrameReport& report) {
  const Rigid3 cam_from_world = marker_fusion_.fix()->world_from_cam.Inverse();
  report.cam_from_world = cam_from_world;
  report.marker_pose = true;
  TrackedPose pose;
  pose.timestamp_s = frame.timestamp_s;
  pose.cam_from_reference = cam_from_world;
  pose.cam_from_world = cam_from_world;
  pose.in_world = true;
  pose.seen_markers = frame.markers;
  poses_.push_back(pose);
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_marker_only_poses;
}

}  // namespace arucoslam
