// System's place recognition: one PlaceRecognition per map (keyframe database, loop
// closing, global BA), relocalisation of lost frames, and following loop corrections.
#include <iterator>

#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

void System::MakePlaceRecognition() {
  places_.reset();
  seen_corrections_ = 0;
  keyframe_poses_.clear();
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

void System::ReanchorOrphanPoses() {
  std::map<KeyframeId, Rigid3> now;
  map_->Read([&](const MapData& data) {
    for (const auto& [id, keyframe] : data.keyframes()) now.emplace(id, keyframe.cam_from_world);
    return 0;
  });
  std::map<double, KeyframeId> by_time;
  for (TrackedPose& pose : poses_) {
    if (!pose.reference.IsValid() || now.count(pose.reference) != 0) continue;
    const auto last = keyframe_poses_.find(pose.reference);
    if (last == keyframe_poses_.end() || now.empty()) continue;
    if (by_time.empty()) {
      map_->Read([&](const MapData& data) {
        for (const auto& [id, keyframe] : data.keyframes()) by_time.emplace(keyframe.timestamp_s, id);
        return 0;
      });
    }
    auto nearest = by_time.lower_bound(pose.timestamp_s);
    if (nearest == by_time.end() ||
        (nearest != by_time.begin() &&
         pose.timestamp_s - std::prev(nearest)->first < nearest->first - pose.timestamp_s)) {
      nearest = std::prev(nearest);
    }
    const KeyframeId anchor = nearest->second;
    if (now.count(anchor) == 0) continue;
    pose.cam_from_world = PoseFromReference(pose, last->second);
    pose.reference = anchor;
    pose.reference_scale = ReferenceScale(anchor);
    pose.cam_from_reference = pose.cam_from_world * now.at(anchor).Inverse();
  }
  keyframe_poses_ = std::move(now);
}

void System::RefreshKeyframePoseCache() {
  if (!places_) return;
  keyframe_poses_.clear();
  map_->Read([&](const MapData& data) {
    for (const auto& [id, keyframe] : data.keyframes()) {
      keyframe_poses_.emplace(id, keyframe.cam_from_world);
    }
    return 0;
  });
}

void System::FollowMapCorrections() {
  if (places_) ReanchorOrphanPoses();
  const bool places_moved = places_ && places_->corrections() != seen_corrections_;
  const int marker_corrections = anchoring_.stats().num_drift_corrections;
  const bool markers_moved = marker_corrections != seen_marker_corrections_;
  if (!places_moved && !markers_moved) return;
  if (places_) seen_corrections_ = places_->corrections();
  seen_marker_corrections_ = marker_corrections;
  if (tracker_->state() != TrackingState::kTracking || poses_.empty()) return;
  const TrackedPose& last = poses_.back();
  const std::optional<Rigid3> reference = map_->Read([&](const MapData& data) {
    const Keyframe* keyframe = data.FindKeyframe(last.reference);
    return keyframe ? std::optional<Rigid3>(keyframe->cam_from_world) : std::nullopt;
  });
  if (!reference) return;
  // world_now_from_world_then: the camera keeps its pose relative to its reference, its
  // surroundings (and so its velocity) scaled as the reference's.
  const Rigid3 cam_from_world_now = PoseFromReference(last, *reference);
  const double scale = ReferenceScale(last.reference) / last.reference_scale;
  tracker_->ApplySimilarity(Sim3(cam_from_world_now.Inverse()) *
                            Sim3(scale, Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero()) *
                            Sim3(last.cam_from_world));
}

double System::ReferenceScale(KeyframeId reference) const {
  return places_ && reference.IsValid() ? places_->KeyframeScale(reference) : 1.0;
}

Rigid3 System::PoseFromReference(const TrackedPose& pose,
                                 const Rigid3& reference_cam_from_world) const {
  Rigid3 cam_from_reference = pose.cam_from_reference;
  cam_from_reference.translation *= ReferenceScale(pose.reference) / pose.reference_scale;
  return cam_from_reference * reference_cam_from_world;
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
