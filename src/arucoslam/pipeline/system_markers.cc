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
  if (!marker_frontend_) return;
  marker_mapping_.AdoptWorldOrigin(detections, frame.camera);
  MapPrediction prediction;
  prediction.world_aligned = anchoring_.aligned();
  prediction.tracking = tracker_->state() == TrackingState::kTracking;
  prediction.predicted_cam_from_map = tracker_->PredictedPose();
  marker_frontend_->Locate(detections, *marker_mapping_.LocatingMarkers(), prediction,
                           report.index, &frame, &marker_fusion_);
  report.num_markers = marker_fusion_.num_markers();
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
    mapping_busy_ = false;
    StartMappingThread();
    ARUCOSLAM_LOG_DEBUG("world re-alignment stopped: the merged map is linked to this one");
    return;
  }
  anchoring_.DropOutlierFixes(*decision);
  // A merged map not linked yet stays where it is (already in the world).
  const std::set<KeyframeId>* stay = absorbed.empty() ? nullptr : &absorbed;
  const std::unique_lock<std::mutex> places_lock = LockPlacesForMapMove();
  // On a re-alignment the markers mapped in the previous estimate of the world move too.
  MarkerLandmarks* mapped = marker_mapping_.live_landmarks();
  map_->Write([&](MapData& data) { ApplyWorldAlignment(world_from_map, &data, mapped, stay); });
  marker_mapping_.ApplySimilarity(world_from_map, stay);
  StartMarkerMapping();
  tracker_->ApplySimilarity(world_from_map);
  pose_history_.MoveIntoWorld(world_from_map, /*realigned=*/anchoring_.aligned(), absorbed);
  if (frame.cam_from_world) {
    frame.cam_from_world = world_from_map.TransformPose(frame.cam_from_world->Inverse()).Inverse();
  }
  if (MergeClosedMap()) CorrectAcrossBridge();
  mapping_busy_ = false;
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
  pose_history_.RecordMarkerPose(frame, cam_from_world);
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_marker_only_poses;
}

}  // namespace arucoslam
