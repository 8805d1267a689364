// MapLifecycle's current map: starting from a saved map and relocalising into it, the place
// database's relocalisation and loop corrections, and the outputs of all maps of the run.
#include "arucoslam/slam/map_lifecycle.h"

#include <algorithm>
#include <optional>
#include <utility>

#include "arucoslam/util/logging.h"

namespace arucoslam {

MapLifecycle::MapLifecycle(const FrameFlowOptions& options, PlaceIndexFactory make_places,
                           FrameFlowStats* stats, std::mutex* stats_mutex)
    : tracker_options_(options.tracker),
      correction_graph_(options.world_anchoring.marker_correction_graph),
      pose_consistency_(options.pose_consistency),
      marker_world_(options.marker_map.has_value()),
      make_places_(std::move(make_places)),
      stats_(stats),
      stats_mutex_(stats_mutex),
      session_(options.map_session, options.marker_map.has_value()),
      loaded_map_relocalizer_(options.tracker) {}

MapLifecycle::~MapLifecycle() = default;

void MapLifecycle::MakePlaces(const MapLifecycleParts& parts) {
  places_.reset();
  seen_corrections_ = 0;
  parts.pose_history.ForgetKeyframePoses();
  places_ = make_places_(parts.map);
}

void MapLifecycle::StartFromMap(const MapLifecycleParts& parts, MapData map, bool world_aligned,
                                bool localize_only) {
  parts.map.Write([&map](MapData& data) { data = std::move(map); });
  map_loaded_ = true;
  localize_only_ = localize_only;
  parts.anchoring.StartLoadedMap(world_aligned);
  if (places_) {
    places_->SetMetricMap(world_aligned);
    places_->IndexExistingKeyframes();
  }
}

bool MapLifecycle::RelocalizeInLoadedMap(const MapLifecycleParts& parts, Frame& frame,
                                         FrameReport& report) {
  // Brute-force keyframe matching, for a loaded map without a place database only.
  if (!map_loaded_ || places_) return false;
  const std::optional<int> num_inliers =
      loaded_map_relocalizer_.Relocalize(parts.map, parts.tracker, frame, report.index);
  if (!num_inliers) return false;
  report.num_inliers = *num_inliers;
  report.message = "relocalised in the loaded map";
  AddToStats(stats_, stats_mutex_, &FrameFlowStats::num_map_relocalizations);
  return true;
}

bool MapLifecycle::RelocalizeWithPlaces(const MapLifecycleParts& parts, Frame& frame,
                                        FrameReport& report) {
  if (!places_) return false;
  const std::optional<RelocalizationResult> found = places_->Relocalize(frame);
  if (!found) return false;
  // Look-alike places: in a map aligned to the marker world only a pose that the frame's
  // markers confirm is taken.
  if (marker_world_ && parts.anchoring.aligned() &&
      !parts.marker_fusion.Confirms(found->cam_from_world)) {
    ARUCOSLAM_LOG_DEBUG("frame {}: place relocalisation not confirmed by markers", report.index);
    return false;
  }
  // The database pose is refined against the local map as after a marker relocalisation.
  const TrackingResult result = parts.tracker.TrackFromPose(frame, found->cam_from_world);
  if (result.state != TrackingState::kTracking) return false;
  parts.tracker.SetReferenceKeyframe(found->keyframe);
  report.num_inliers = result.num_inliers;
  report.message = "relocalised from the place database";
  ARUCOSLAM_LOG_DEBUG("frame {}: relocalised from keyframe {}, {} inliers", report.index,
                      found->keyframe.value, result.num_inliers);
  places_->RelocalizationTaken();
  return true;
}

void MapLifecycle::RefreshKeyframePoseCache(const MapLifecycleParts& parts) {
  if (places_) parts.pose_history.RememberKeyframePoses(parts.map);
}

void MapLifecycle::FollowMapCorrections(const MapLifecycleParts& parts) {
  if (places_) parts.pose_history.ReanchorOrphans(parts.map);
  const bool places_moved = places_ && places_->corrections() != seen_corrections_;
  const int marker_corrections = parts.anchoring.stats().num_drift_corrections;
  const bool markers_moved = marker_corrections != seen_marker_corrections_;
  if (!places_moved && !markers_moved) return;
  if (places_) seen_corrections_ = places_->corrections();
  seen_marker_corrections_ = marker_corrections;
  if (parts.tracker.state() != TrackingState::kTracking) return;
  if (const std::optional<Sim3> correction = parts.pose_history.LastPoseCorrection(parts.map)) {
    parts.tracker.ApplySimilarity(*correction);
  }
}

std::unique_lock<std::mutex> MapLifecycle::LockPlacesForMapMove() {
  if (!places_) return {};
  std::unique_lock<std::mutex> lock = places_->LockMapEdits();
  places_->MapMovedExternally();
  // The only outside move is the alignment to the marker world, which makes the map metric.
  places_->SetMetricMap(true);
  return lock;
}

void MapLifecycle::AdjustWholeMapWithMarkers(Map& map, OnlineMarkerMapping& marker_mapping,
                                             const char* when) {
  if (!marker_mapping.AdjustsWholeMap()) return;
  // A global BA of the loop closer may be solving: it is discarded, and the landmarks it
  // writes under this lock are not touched meanwhile.
  const std::unique_lock<std::mutex> places_lock = LockPlacesForMapMove();
  marker_mapping.AdjustWholeMap(&map, when);
}

std::vector<StampedPose> MapLifecycle::KeyframePoses(const Map& map, bool world_aligned) const {
  std::vector<StampedPose> poses = session_.closed_keyframes();
  if (!marker_world_ || world_aligned) {  // else the map is not in the world frame
    map.Read([&](const MapData& data) {
      for (const auto& [id, keyframe] : data.keyframes()) {
        poses.push_back({keyframe.timestamp_s, keyframe.cam_from_world.Inverse()});
      }
      return 0;
    });
  }
  // Ids are not in time order once a closed map was merged (its keyframes numbered anew).
  std::stable_sort(poses.begin(), poses.end(), [](const StampedPose& a, const StampedPose& b) {
    return a.timestamp_s < b.timestamp_s;
  });
  return poses;
}

std::vector<Eigen::Vector3d> MapLifecycle::MapPoints(const Map& map, bool world_aligned) const {
  std::vector<Eigen::Vector3d> points = session_.closed_points();
  if (marker_world_ && !world_aligned) return points;  // not in the world frame
  map.Read([&](const MapData& data) {
    for (const auto& [id, point] : data.map_points()) points.push_back(point.p_in_world);
    return 0;
  });
  return points;
}

}  // namespace arucoslam
