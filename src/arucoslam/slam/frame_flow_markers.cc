// FrameFlow's marker side: relocalisation from a marker pose, marker-only poses, the Sim(3)
// alignment of the keypoint map to the world, and the wiring of the online marker mapping.
#include <optional>
#include <set>
#include <vector>

#include "arucoslam/slam/frame_flow.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

void FrameFlow::MakeLocalMapper() {
  mapper_ = std::make_unique<LocalMapper>(*map_, options_.mapper);
  if (options_.marker_map) {  // keyframes anchoring_ keeps are not culled
    mapper_->SetKeyframeGuard(
        [this](const Keyframe& keyframe) { return anchoring_.KeepsKeyframe(keyframe); });
  }
  if (!options_.inline_mapping && options_.yield_bundle_adjustment) {
    mapper_->SetYieldRequest([this] { return mapping_->KeyframeWaiting(); });
  }
}

bool FrameFlow::RelocalizeWithMarkers(Frame& frame, FrameReport& report) {
  const std::optional<MarkerFix>& fix = marker_fusion_.fix();
  if (!anchoring_.aligned() || !fix) return false;
  const TrackingResult result =
      tracker_->TrackFromPose(frame, fix->world_from_cam.Inverse(), fix->markers);
  if (result.state != TrackingState::kTracking) return false;
  report.num_inliers = result.num_inliers;
  report.message = "relocalised from markers";
  ARUCOSLAM_LOG_DEBUG("frame {}: relocalised from markers, {} inliers", report.index,
                      result.num_inliers);
  CountStat(&FrameFlowStats::num_marker_relocalizations);
  return true;
}

void FrameFlow::MaybeAlignWorld(Frame& frame) {
  const std::optional<AlignmentDecision> decision = anchoring_.DecideAlignment(*map_);
  if (!decision) return;
  const std::vector<WorldAnchor>& anchors = decision->anchors;
  const WorldAlignment& alignment = decision->alignment;
  const Sim3& world_from_map = alignment.world_from_map;
  mapping_->Pause();  // every queued keyframe is mapped first; mapping is idle below
  const MapSession& session = lifecycle_.session();
  const std::set<KeyframeId>& absorbed = session.absorbed_keyframes();
  if (anchoring_.aligned() && !absorbed.empty() && session.LinkedToAbsorbedMap(*map_)) {
    // A merged map that shares points with this one now (a loop, fused points): a
    // re-alignment from this map's anchors alone would tear them apart. Markers correct the
    // map by fusion from here on (drift correction, marker corners in bundle adjustment).
    anchoring_.StopRealigning();
    mapping_->Resume();
    ARUCOSLAM_LOG_DEBUG("world re-alignment stopped: the merged map is linked to this one");
    return;
  }
  anchoring_.DropOutlierFixes(*decision);
  // A merged map not linked yet stays where it is (already in the world).
  const std::set<KeyframeId>* stay = absorbed.empty() ? nullptr : &absorbed;
  const std::unique_lock<std::mutex> places_lock = lifecycle_.LockPlacesForMapMove();
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
  lifecycle_.MergeClosedMap(Parts());
  mapping_->Resume();
  ARUCOSLAM_LOG_DEBUG("keypoint map {}aligned to the marker world: scale {:.4f}, {} of {} "
                      "anchors, rms {:.3f} m",
                      anchoring_.aligned() ? "re-" : "", world_from_map.scale,
                      alignment.num_inliers, anchors.size(), alignment.rms_m);
  anchoring_.AlignmentApplied(*decision);
  marker_fusion_.MapEnteredWorld(frame.timestamp_s);  // the anchors agree with the map
  lifecycle_.RefreshKeyframePoseCache(Parts());
}

void FrameFlow::RecordMarkerPose(const Frame& frame, FrameReport& report) {
  const Rigid3 cam_from_world = marker_fusion_.fix()->world_from_cam.Inverse();
  report.cam_from_world = cam_from_world;
  report.marker_pose = true;
  pose_history_.RecordMarkerPose(frame, cam_from_world);
  CountStat(&FrameFlowStats::num_marker_only_poses);
}

void FrameFlow::StartMarkerMapping() {
  if (!marker_mapping_.Start()) return;
  PlaceIndex* places = lifecycle_.places();
  if (MarkerLandmarks* landmarks = marker_mapping_.landmarks_for_bundle_adjustment()) {
    mapper_->SetMarkerLandmarks(landmarks);
    // The caller holds the places' edit lock (LockPlacesForMapMove).
    if (places) places->SetMarkerLandmarks(landmarks);
  }
  if (places && options_.world_anchoring.priors_in_loops) {
    places->SetLoopPosePriors([this] { return anchoring_.KnownMarkerPriors(); },
                               options_.world_anchoring.marker_correction_graph);
  }
  // Keyframes mapped before the alignment are recorded now, at their aligned poses.
  for (const KeyframeId& id : marker_mapping_.UnfedKeyframes(*map_)) {
    marker_mapping_.AddKeyframe(*map_, id);
  }
}

void FrameFlow::CorrectDriftWithMarkers(KeyframeId keyframe) {
  const std::optional<DriftCorrectionDecision> decision =
      marker_mapping_.DecideDriftCorrection(*map_, anchoring_, keyframe);
  if (!decision) return;
  PlaceIndex* places = lifecycle_.places();
  if (places) places->MapMovedExternally();
  const EssentialGraphResult result = marker_mapping_.CorrectDrift(
      map_.get(), keyframe, *decision, options_.world_anchoring.marker_correction_graph);
  if (!result.applied) return;
  if (places) places->RecordScaleChanges(result.scale_changes);
  anchoring_.DriftCorrected();
}

}  // namespace arucoslam
