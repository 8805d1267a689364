#include "arucoslam/slam/marker_world.h"

#include <optional>
#include <set>
#include <vector>

#include "arucoslam/slam/world_alignment.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

MarkerWorld::MarkerWorld(const FrameFlowOptions& options, FrameFlowStats* stats,
                         std::mutex* stats_mutex)
    : correction_graph_(options.world_anchoring.marker_correction_graph),
      priors_in_loops_(options.world_anchoring.priors_in_loops),
      stats_(stats),
      stats_mutex_(stats_mutex) {}

bool MarkerWorld::Relocalize(const MarkerWorldParts& parts, Frame& frame, FrameReport& report) {
  const std::optional<MarkerFix>& fix = parts.marker_fusion.fix();
  if (!parts.anchoring.aligned() || !fix) return false;
  const TrackingResult result =
      parts.tracker.TrackFromPose(frame, fix->world_from_cam.Inverse(), fix->markers);
  if (result.state != TrackingState::kTracking) return false;
  report.num_inliers = result.num_inliers;
  report.message = "relocalised from markers";
  ARUCOSLAM_LOG_DEBUG("frame {}: relocalised from markers, {} inliers", report.index,
                      result.num_inliers);
  AddToStats(stats_, stats_mutex_, &FrameFlowStats::num_marker_relocalizations);
  return true;
}

void MarkerWorld::MaybeAlign(const MarkerWorldParts& parts, Frame& frame) {
  WorldAnchoring& anchoring = parts.anchoring;
  const std::optional<AlignmentDecision> decision = anchoring.DecideAlignment(parts.map);
  if (!decision) return;
  const std::vector<WorldAnchor>& anchors = decision->anchors;
  const WorldAlignment& alignment = decision->alignment;
  const Sim3& world_from_map = alignment.world_from_map;
  parts.mapping.Hold();  // no keyframe is being mapped below; the queued ones move with the map
  const MapSession& session = parts.lifecycle.session();
  const std::set<KeyframeId>& absorbed = session.absorbed_keyframes();
  if (anchoring.aligned() && !absorbed.empty() && session.LinkedToAbsorbedMap(parts.map)) {
    // A merged map that shares points with this one now (a loop, fused points): a
    // re-alignment from this map's anchors alone would tear them apart. Markers correct the
    // map by fusion from here on (drift correction, marker corners in bundle adjustment).
    anchoring.StopRealigning();
    parts.mapping.Release();
    ARUCOSLAM_LOG_DEBUG("world re-alignment stopped: the merged map is linked to this one");
    return;
  }
  anchoring.DropOutlierFixes(*decision);
  // A merged map not linked yet stays where it is (already in the world).
  const std::set<KeyframeId>* stay = absorbed.empty() ? nullptr : &absorbed;
  const std::unique_lock<std::mutex> places_lock = parts.lifecycle.LockPlacesForMapMove();
  // On a re-alignment the markers mapped in the previous estimate of the world move too.
  MarkerLandmarks* mapped = parts.marker_mapping.live_landmarks();
  parts.map.Write([&](MapData& data) { ApplyWorldAlignment(world_from_map, &data, mapped, stay); });
  parts.marker_mapping.ApplySimilarity(world_from_map, stay);
  StartMarkerMapping(parts);
  parts.tracker.ApplySimilarity(world_from_map);
  parts.pose_history.MoveIntoWorld(world_from_map, /*realigned=*/anchoring.aligned(), absorbed);
  if (frame.cam_from_world) {
    frame.cam_from_world = world_from_map.TransformPose(frame.cam_from_world->Inverse()).Inverse();
  }
  parts.lifecycle.MergeClosedMap(parts.ForLifecycle());
  parts.mapping.Release();
  ARUCOSLAM_LOG_DEBUG(
      "keypoint map {}aligned to the marker world: scale {:.4f}, {} of {} "
      "anchors, rms {:.3f} m",
      anchoring.aligned() ? "re-" : "", world_from_map.scale, alignment.num_inliers, anchors.size(),
      alignment.rms_m);
  anchoring.AlignmentApplied(*decision);
  parts.marker_fusion.MapEnteredWorld();
  parts.lifecycle.RefreshKeyframePoseCache(parts.ForLifecycle());
}

void MarkerWorld::RecordMarkerPose(const MarkerWorldParts& parts, const Frame& frame,
                                   FrameReport& report) {
  const Rigid3 cam_from_world = parts.marker_fusion.fix()->world_from_cam.Inverse();
  report.cam_from_world = cam_from_world;
  report.marker_pose = true;
  parts.pose_history.RecordMarkerPose(frame, cam_from_world);
  AddToStats(stats_, stats_mutex_, &FrameFlowStats::num_marker_only_poses);
}

void MarkerWorld::StartMarkerMapping(const MarkerWorldParts& parts) {
  OnlineMarkerMapping& marker_mapping = parts.marker_mapping;
  if (!marker_mapping.Start()) return;
  PlaceIndex* places = parts.lifecycle.places();
  if (MarkerLandmarks* landmarks = marker_mapping.landmarks_for_bundle_adjustment()) {
    parts.mapper.SetMarkerLandmarks(landmarks);
    // The caller holds the places' edit lock (LockPlacesForMapMove).
    if (places) places->SetMarkerLandmarks(landmarks);
  }
  if (places && priors_in_loops_) {
    places->SetLoopPosePriors(
        [&anchoring = parts.anchoring] { return anchoring.KnownMarkerPriors(); },
        correction_graph_);
  }
  // Keyframes mapped before the alignment are recorded now, at their aligned poses.
  for (const KeyframeId& id : marker_mapping.UnfedKeyframes(parts.map)) {
    marker_mapping.AddKeyframe(parts.map, id);
  }
}

void MarkerWorld::CorrectDrift(Map& map, KeyframeId keyframe, WorldAnchoring& anchoring,
                               OnlineMarkerMapping& marker_mapping, PlaceIndex* places) {
  const std::optional<DriftCorrectionDecision> decision =
      marker_mapping.DecideDriftCorrection(map, anchoring, keyframe);
  if (!decision) return;
  if (places) places->MapMovedExternally();
  const EssentialGraphResult result =
      marker_mapping.CorrectDrift(&map, keyframe, *decision, correction_graph_);
  if (!result.applied) return;
  if (places) places->RecordScaleChanges(result.scale_changes);
  anchoring.DriftCorrected();
}

}  // namespace arucoslam
