// System's marker handling: locating each frame in the known marker map, marker-only poses,
// relocalisation from a marker pose, and the Sim(3) alignment of the keypoint map to the world.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {
namespace {

Eigen::Vector2d UndistortedPixel(const CameraModel& camera, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d normalised = camera.Unproject(pixel);
  return {camera.fx * normalised.x() + camera.cx, camera.fy * normalised.y() + camera.cy};
}

// Largest distance between two anchors' camera centres, metres.
double Baseline(const std::vector<WorldAnchor>& anchors) {
  double baseline = 0.0;
  for (std::size_t i = 0; i < anchors.size(); ++i) {
    for (std::size_t j = i + 1; j < anchors.size(); ++j) {
      baseline = std::max(baseline, (anchors[i].world_from_cam.translation -
                                     anchors[j].world_from_cam.translation).norm());
    }
  }
  return baseline;
}

// Distance from the camera at `world_from_cam` to its nearest located marker, in that
// marker's sides.
double NearestMarkerInSides(const CameraLocation& location, const Rigid3& world_from_cam,
                            const MarkerMap& known) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const int id : location.marker_ids) {
    const MarkerInfo* info = known.Find(id);
    const double distance =
        (info->world_from_marker.translation - world_from_cam.translation).norm();
    nearest = std::min(nearest, distance / info->size);
  }
  return nearest;
}

// For the logs: how far both solutions of an ambiguous location lie from a prediction.
std::string DistancesFrom(const CameraLocation& location, const Rigid3& predicted) {
  const auto describe = [&predicted](const Rigid3& pose) {
    return fmt::format("{:.1f} deg {:.2f} m",
                       RotationAngle(pose.rotation.inverse() * predicted.rotation) * 180.0 / M_PI,
                       (pose.translation - predicted.translation).norm());
  };
  return "best " + describe(location.world_from_cam) + ", other " +
         describe(*location.alternative_world_from_cam);
}

// The same for an orientation alone (the map's voted world rotation).
std::string AnglesFrom(const CameraLocation& location, const Eigen::Quaterniond& world_from_cam) {
  const auto describe = [&world_from_cam](const Rigid3& pose) {
    return fmt::format("{:.1f} deg",
                       RotationAngle(pose.rotation.inverse() * world_from_cam) * 180.0 / M_PI);
  };
  return "best " + describe(location.world_from_cam) + ", other " +
         describe(*location.alternative_world_from_cam);
}

}  // namespace

std::optional<System::MarkerFix> System::LocateWithMarkers(
    Frame& frame, const std::vector<MarkerDetection>& detections, FrameReport& report) {
  if (!options_.marker_map) return std::nullopt;
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
  const MarkerMap& known = locating ? *locating : *options_.marker_map;
  const CameraLocation location = LocateCamera(detections, known, camera_, options_.locator);
  report.num_markers = static_cast<int>(location.marker_ids.size());
  std::optional<MarkerFix> fix;
  // An ambiguous location counts only as the solution the motion prediction settles on.
  bool by_map_rotation = false, by_covisible = false;
  AmbiguityChoice choice =
      location.found && location.quality.ambiguous && options_.resolve_ambiguity_by_motion
          ? ResolveByMotion(location, frame.timestamp_s, &by_map_rotation)
          : AmbiguityChoice::kNone;
  if (choice == AmbiguityChoice::kNone && location.found && location.quality.ambiguous &&
      options_.resolve_ambiguity_by_covisible_markers) {
    choice = covisible_vote_.Add(location, UnknownDetections(location, detections),
                                 UnknownMarkerSize(*options_.marker_map,
                                                   options_.marker_mapping.unknown_marker_size_m),
                                 frame.camera);
    by_covisible = choice != AmbiguityChoice::kNone;
  }
  ambiguous_location_.reset();
  const bool resolved = choice != AmbiguityChoice::kNone;
  const bool alternative = choice == AmbiguityChoice::kAlternative;
  const Rigid3 world_from_cam =
      resolved ? *ChosenPose(location, choice) : location.world_from_cam;
  double nearest_sides = std::numeric_limits<double>::infinity();
  const bool usable =
      location.found && UsableLocation(location, alternative, known, &nearest_sides);
  if (location.found && location.quality.ambiguous && location.alternative_world_from_cam &&
      usable && !world_aligned_ && options_.resolve_ambiguity_by_map_rotation) {
    ambiguous_location_ = location;  // votes for the map's orientation once tracked
  }
  if (location.found && (!location.quality.ambiguous || resolved) && usable) {
    fix.emplace();
    fix->world_from_cam = world_from_cam;
    fix->disambiguated_by_motion = resolved;
    fix->nearest_marker_sides = nearest_sides;
    fix->known_markers_only = std::all_of(
        location.marker_ids.begin(), location.marker_ids.end(),
        [&](int id) {
          const MarkerInfo* info = options_.marker_map->Find(id);
          return info != nullptr && info->fixed;
        });
    for (const MarkerDetection& detection : detections) {
      if (!std::binary_search(location.marker_ids.begin(), location.marker_ids.end(),
                              detection.id)) {
        continue;
      }
      const MarkerInfo* info = known.Find(detection.id);
      MarkerPoseObservation observation;
      observation.world_from_marker = info->world_from_marker;
      observation.size = info->size;
      for (int c = 0; c < 4; ++c) {
        observation.corners_px[c] = UndistortedPixel(frame.camera, detection.corners[c]);
      }
      fix->markers.push_back(observation);
    }
  }
  std::lock_guard lock(stats_mutex_);
  const double locating_ms = watch.ElapsedMilliseconds();
  stats_.marker_ms.Add(detection_ms_ + locating_ms);
  stats_.marker_wait_ms.Add(marker_wait_ms_ + locating_ms);
  detection_ms_ = marker_wait_ms_ = 0.0;
  if (fix) {
    fix_motion_.Add(frame.timestamp_s, fix->world_from_cam);
    ++stats_.num_marker_frames;
    if (fix->disambiguated_by_motion) {
      ++stats_.num_marker_disambiguations;
      if (by_map_rotation) ++stats_.num_map_rotation_disambiguations;
      if (by_covisible) ++stats_.num_covisible_disambiguations;
      ARUCOSLAM_LOG_DEBUG("frame {}: ambiguous marker {} settled by the motion prediction{}",
                          report.index, location.marker_ids.front(),
                          alternative ? " (IPPE's second solution)" : "");
    }
  }
  return fix;
}

std::vector<MarkerDetection> System::UnknownDetections(
    const CameraLocation& location, const std::vector<MarkerDetection>& detections) const {
  std::vector<MarkerDetection> unknown;
  for (const MarkerDetection& detection : detections) {
    if (std::binary_search(location.unknown_marker_ids.begin(), location.unknown_marker_ids.end(),
                           detection.id)) {
      unknown.push_back(detection);
    }
  }
  return unknown;
}

bool System::UsableLocation(const CameraLocation& location, bool alternative,
                            const MarkerMap& known, double* nearest_sides) const {
  const double rms_px = alternative ? location.quality.alternative_rms_px
                                    : location.quality.reprojection_rms_px;
  const Rigid3& world_from_cam =
      alternative ? *location.alternative_world_from_cam : location.world_from_cam;
  *nearest_sides = NearestMarkerInSides(location, world_from_cam, known);
  return rms_px <= options_.max_marker_rms_px &&
         *nearest_sides <= options_.max_marker_distance_sides;
}

AmbiguityChoice System::ResolveByMotion(const CameraLocation& location, double timestamp_s,
                                        bool* by_map_rotation) const {
  // The map's motion model (keypoint poses in the world; before the alignment, orientations
  // through the voted world rotation) and the recent marker fixes predict independently;
  // when both settle the ambiguity they must agree.
  *by_map_rotation = false;
  if (!location.alternative_world_from_cam) return AmbiguityChoice::kNone;
  AmbiguityChoice by_tracker = AmbiguityChoice::kNone;
  bool tracker_prediction = false, fixes_prediction = false, map_rotation_prediction = false;
  if (world_aligned_) {
    if (const std::optional<Rigid3> predicted = tracker_->PredictedPose()) {
      tracker_prediction = true;
      by_tracker = ResolveAmbiguity(location, predicted->Inverse(), options_.ambiguity_gates);
      ARUCOSLAM_LOG_DEBUG("t {:.3f}: ambiguous marker vs tracker prediction: {}", timestamp_s,
                          DistancesFrom(location, predicted->Inverse()));
    }
  } else if (options_.resolve_ambiguity_by_map_rotation && rotation_vote_.WorldFromMap() &&
             tracker_->state() == TrackingState::kTracking) {
    if (const std::optional<Rigid3> predicted = tracker_->PredictedPose()) {
      tracker_prediction = map_rotation_prediction = true;
      const Eigen::Quaterniond world_from_cam =
          *rotation_vote_.WorldFromMap() * predicted->rotation.inverse();
      by_tracker =
          ResolveAmbiguityByRotation(location, world_from_cam, options_.map_rotation_gates);
      ARUCOSLAM_LOG_DEBUG("t {:.3f}: ambiguous marker vs the map's voted orientation: {}",
                          timestamp_s, AnglesFrom(location, world_from_cam));
    }
  }
  AmbiguityChoice by_fixes = AmbiguityChoice::kNone;
  if (const std::optional<Rigid3> predicted = fix_motion_.Predict(timestamp_s)) {
    fixes_prediction = true;
    by_fixes = ResolveAmbiguity(location, *predicted, options_.ambiguity_gates);
    ARUCOSLAM_LOG_DEBUG("t {:.3f}: ambiguous marker vs marker-fix prediction: {}", timestamp_s,
                        DistancesFrom(location, *predicted));
  }
  if (!tracker_prediction && !fixes_prediction) {
    ARUCOSLAM_LOG_DEBUG("t {:.3f}: ambiguous marker, no motion prediction", timestamp_s);
  }
  if (by_tracker == AmbiguityChoice::kNone) return by_fixes;
  if (by_fixes != AmbiguityChoice::kNone && by_fixes != by_tracker) return AmbiguityChoice::kNone;
  // Counted as the map rotation's only when the fixes did not settle it too.
  *by_map_rotation = map_rotation_prediction && by_fixes == AmbiguityChoice::kNone;
  return by_tracker;
}

void System::VoteForWorldRotation(const Frame& frame) {
  if (!ambiguous_location_ || world_aligned_ || !frame.cam_from_world) return;
  rotation_vote_.Add(*frame.cam_from_world, ambiguous_location_->world_from_cam,
                     *ambiguous_location_->alternative_world_from_cam);
  ambiguous_location_.reset();
}

void System::GuardMarkerKeyframes() {
  if (!options_.marker_map) return;
  keep_marker_keyframes_ = true;
  mapper_->SetKeyframeGuard([this](const Keyframe& keyframe) {
    return keep_marker_keyframes_ && !keyframe.markers.empty();
  });
}

Eigen::Vector3d System::MarkerOffset(const Rigid3& cam_from_world) const {
  return fix_->world_from_cam.translation - cam_from_world.Inverse().translation;
}

bool System::DisagreesWithMarkers(const Rigid3& cam_from_world) const {
  if (!world_aligned_ || !fix_) return false;
  return MarkerOffset(cam_from_world).norm() > options_.max_marker_disagreement_m;
}

void System::ForgetMarkerAgreement() {
  markers_agreed_s_.reset();
  last_marker_offset_.reset();
  drift_frames_ = 0;
  drift_keyframe_wanted_ = false;
}

bool System::TakeDisagreementAsDrift(const Frame& frame, FrameReport& report) {
  if (!options_.correct_drift_beyond_gate || !markers_agreed_s_ || !fix_->known_markers_only) {
    return false;
  }
  const Eigen::Vector3d offset = MarkerOffset(*frame.cam_from_world);
  if (drift_frames_ == 0) {
    // Drift builds up out of the markers' sight or grows a little from frame to frame; a
    // jump away from where the markers just agreed is a wrong place.
    const bool long_unseen =
        frame.timestamp_s - *markers_agreed_s_ >= options_.min_drift_interval_s;
    const bool gradual =
        last_marker_offset_ && (offset - *last_marker_offset_).norm() <= options_.max_drift_step_m;
    if (!long_unseen && !gradual) return false;
    ARUCOSLAM_LOG_DEBUG(
        "frame {}: keypoint pose {:.2f} m from the markers' location, {:.1f} s "
        "after they last agreed: drift, the map is corrected",
        report.index, offset.norm(), frame.timestamp_s - *markers_agreed_s_);
    drift_keyframe_wanted_ = true;
    std::lock_guard lock(stats_mutex_);
    ++stats_.num_drift_disagreements;
  }
  // The correction did not bring the map back in time: from here on a look-alike place.
  if (++drift_frames_ > options_.max_drift_correction_frames) {
    ForgetMarkerAgreement();
    return false;
  }
  return true;
}

void System::NoteMarkerAgreement(const Frame& frame, bool relocalized) {
  if (!world_aligned_) return;
  const bool agrees = fix_ && !DisagreesWithMarkers(*frame.cam_from_world);
  if (relocalized && !agrees) {  // not confirmed by the markers: a break in the tracking
    ForgetMarkerAgreement();
    return;
  }
  if (fix_) last_marker_offset_ = MarkerOffset(*frame.cam_from_world);
  if (agrees) {
    markers_agreed_s_ = frame.timestamp_s;
    drift_frames_ = 0;
    drift_keyframe_wanted_ = false;
  }
}

bool System::RelocalizeWithMarkers(Frame& frame, FrameReport& report) {
  if (!world_aligned_ || !fix_) return false;
  const TrackingResult result =
      tracker_->TrackFromPose(frame, fix_->world_from_cam.Inverse(), fix_->markers);
  if (result.state != TrackingState::kTracking) return false;
  report.num_inliers = result.num_inliers;
  report.message = "relocalised from markers";
  ARUCOSLAM_LOG_DEBUG("frame {}: relocalised from markers, {} inliers", report.index,
                      result.num_inliers);
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_marker_relocalizations;
  return true;
}

void System::AddAnchor(KeyframeId keyframe, const std::optional<MarkerFix>& fix) {
  if (!fix || !keyframe.IsValid()) return;
  {
    std::lock_guard lock(keyframe_fixes_mutex_);
    keyframe_fixes_[keyframe] = *fix;
  }
  if (world_aligned_ && next_alignment_anchors_ > options_.max_realignment_anchors) return;
  anchors_.push_back({keyframe, fix->world_from_cam});
}

void System::MaybeAlignWorld(Frame* frame) {
  const int needed = std::max(options_.min_alignment_anchors, next_alignment_anchors_);
  if (static_cast<int>(anchors_.size()) < needed) return;
  std::vector<WorldAnchor> anchors;
  std::vector<MarkerAnchor> live;  // anchors whose keyframe is still in the map
  map_->Read([&](const MapData& data) {
    for (const MarkerAnchor& anchor : anchors_) {
      const Keyframe* keyframe = data.FindKeyframe(anchor.keyframe);
      if (keyframe == nullptr) continue;
      live.push_back(anchor);
      WorldAnchor world_anchor;
      world_anchor.keyframe = anchor.keyframe;
      world_anchor.cam_from_map = keyframe->cam_from_world;
      world_anchor.world_from_cam = anchor.world_from_cam;
      anchors.push_back(world_anchor);
    }
    return 0;
  });
  anchors_ = std::move(live);
  if (static_cast<int>(anchors.size()) < needed ||
      Baseline(anchors) < options_.min_alignment_baseline_m) {
    ARUCOSLAM_LOG_DEBUG("world alignment waits: {} anchors with keyframes ({} needed), baseline "
                        "{:.2f} m", anchors.size(), needed, Baseline(anchors));
    return;
  }
  const WorldAlignment alignment = EstimateWorldFromMap(anchors, options_.alignment);
  if (!alignment.success || alignment.rms_m > options_.max_alignment_rms_m ||
      (!world_aligned_ && alignment.world_from_map.scale > options_.max_alignment_scale)) {
    ARUCOSLAM_LOG_DEBUG("world alignment refused ({} anchors): {} rms {:.3f} m, scale {:.2f}",
                        anchors.size(), alignment.failure, alignment.rms_m,
                        alignment.world_from_map.scale);
    return;
  }
  const Sim3& world_from_map = alignment.world_from_map;
  StopMappingThread();  // every queued keyframe is mapped first; mapping is idle below
  if (world_aligned_ && !absorbed_keyframes_.empty() && LinkedToAbsorbedMap()) {
    // A merged map that shares points with this one now (a loop, fused points): a
    // re-alignment from this map's anchors alone would tear them apart. Markers correct the
    // map by fusion from here on (drift correction, marker corners in bundle adjustment).
    next_alignment_anchors_ = options_.max_realignment_anchors + 1;
    anchors_.clear();
    mapping_busy_ = false;
    StartMappingThread();
    ARUCOSLAM_LOG_DEBUG("world re-alignment stopped: the merged map is linked to this one");
    return;
  }
  {
    // An anchor the alignment found an outlier has a wrong marker location (a mirrored
    // one-marker solution, a far marker): no drift correction may pull the map towards it.
    std::lock_guard lock(keyframe_fixes_mutex_);
    for (std::size_t i = 0; i < anchors.size(); ++i) {
      if (!alignment.inliers[i]) keyframe_fixes_.erase(anchors[i].keyframe);
    }
  }
  // A merged map not linked yet stays where it is (already in the world).
  const std::set<KeyframeId>* stay = absorbed_keyframes_.empty() ? nullptr : &absorbed_keyframes_;
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
    const bool moves = !pose.in_world || (world_aligned_ && pose.reference.IsValid() &&
                                           absorbed_keyframes_.count(pose.reference) == 0);
    if (!moves) continue;
    pose.cam_from_world = to_world(pose.cam_from_world);
    pose.cam_from_reference.translation *= world_from_map.scale;
    pose.in_world = true;
  }
  if (frame != nullptr && frame->cam_from_world) {
    frame->cam_from_world = to_world(*frame->cam_from_world);
  }
  next_alignment_anchors_ = 2 * static_cast<int>(anchors.size());
  if (MergeClosedMap()) CorrectAcrossBridge();
  mapping_busy_ = false;
  StartMappingThread();
  ARUCOSLAM_LOG_DEBUG("keypoint map {}aligned to the marker world: scale {:.4f}, {} of {} "
                      "anchors, rms {:.3f} m",
                      world_aligned_ ? "re-" : "", world_from_map.scale, alignment.num_inliers,
                      anchors.size(), alignment.rms_m);
  world_aligned_ = true;
  if (frame != nullptr) {  // the anchors agree with the map
    markers_agreed_s_ = frame->timestamp_s;
    last_marker_offset_.reset();
  }
  rotation_vote_.Clear();
  keep_marker_keyframes_ = false;
  RefreshKeyframePoseCache();
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_world_alignments;
}

void System::RecordMarkerPose(const Frame& frame, FrameReport& report) {
  const Rigid3 cam_from_world = fix_->world_from_cam.Inverse();
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
