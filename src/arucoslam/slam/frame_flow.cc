#include "arucoslam/slam/frame_flow.h"

#include <stdexcept>
#include <string>
#include <utility>

#include "arucoslam/util/logging.h"

namespace arucoslam {
namespace {

// `options`, or std::invalid_argument naming their first bad field.
const FrameFlowOptions& Checked(const FrameFlowOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("FrameFlowOptions: " + why);
  return options;
}

MarkerFusion MakeMarkerFusion(const FrameFlowOptions& options, const CameraModel& camera) {
  if (!options.marker_map) return MarkerFusion(options.marker_fusion, camera, MarkerMap(), 0.0);
  const double unknown_size = UnknownMarkerSize(
      *options.marker_map, options.marker_mapping.mapper.unknown_marker_size_m);
  return MarkerFusion(options.marker_fusion, camera, *options.marker_map, unknown_size);
}

}  // namespace

FrameFlow::FrameFlow(const CameraModel& camera, const FrameFlowOptions& options,
                     MappingControl* mapping, PlaceIndexFactory make_places,
                     FrameFlowStats* stats, std::mutex* stats_mutex)
    : options_(Checked(options)),
      camera_(camera),
      tracked_camera_(camera),
      radial_calibration_(options.radial_calibration),
      mapping_(mapping),
      stats_(stats),
      stats_mutex_(stats_mutex),
      map_initializer_(camera, options.initialization),
      pose_history_(options.refine_frame_poses,
                    [this](KeyframeId id) {
                      const PlaceIndex* places = lifecycle_.places();
                      return places ? places->KeyframeScale(id) : 1.0;
                    }),
      marker_fusion_(MakeMarkerFusion(options, camera)),
      anchoring_(options.world_anchoring),
      marker_mapping_(options.marker_map, options.marker_mapping),
      marker_world_(options, stats, stats_mutex),
      lifecycle_(options, std::move(make_places), stats, stats_mutex) {
  map_ = std::make_unique<Map>();
  tracker_ = std::make_unique<Tracker>(*map_, options_.tracker);
  MakeLocalMapper();
  lifecycle_.MakePlaces(Parts());
}

FrameFlow::~FrameFlow() = default;

void FrameFlow::CountStat(int FrameFlowStats::*counter, int amount) {
  AddToStats(stats_, stats_mutex_, counter, amount);
}

MapPrediction FrameFlow::Prediction(double timestamp_s) const {
  MapPrediction prediction;
  prediction.world_aligned = anchoring_.aligned();
  prediction.tracking = tracker_->state() == TrackingState::kTracking;
  prediction.predicted_cam_from_map = tracker_->PredictedPose(timestamp_s);
  return prediction;
}

void FrameFlow::Process(Frame& frame, FrameReport& report) {
  FollowCalibration(frame);
  const std::optional<MarkerFix>& fix = marker_fusion_.fix();
  if (tracker_->state() == TrackingState::kNotInitialized) {
    lifecycle_.map_loaded() ? LocalizeInLoadedMap(frame, report) : Initialize(frame, report);
  } else {
    Track(frame, report);
  }
  // A loaded map that stays outside the marker world takes no marker-only poses.
  const bool marker_poses = anchoring_.aligned() || !localize_only();
  if (!report.cam_from_world && fix && marker_poses) {
    marker_world_.RecordMarkerPose(MarkerParts(), frame, report);
  }
  if (!localize_only()) marker_mapping_.AddMarkerView(frame, marker_fusion_.fix());
  // Without a world pose now (none, or a keypoint pose outside the world without a marker
  // location), a frame that saw markers may be located at the end.
  const bool world_pose = report.cam_from_world && (anchoring_.aligned() || fix);
  if (!world_pose && !frame.markers.empty()) {
    pose_history_.NoteUnposedMarkerFrame(frame.timestamp_s, frame.markers);
  }
  report.world_aligned = anchoring_.aligned();
  if (fix) report.marker_world_from_cam = fix->world_from_cam;
  const bool in_world = !options_.marker_map || anchoring_.aligned() || report.marker_pose;
  if (report.cam_from_world && in_world) {
    report.online_world_from_cam = report.cam_from_world->Inverse();
  }
  if (options_.marker_map && !report.cam_from_world && frame.markers.empty()) {
    pose_history_.NoteUnposedWithoutMarkers(frame.timestamp_s);
  }
}

void FrameFlow::Initialize(Frame& frame, FrameReport& report) {
  report.state = TrackingState::kNotInitialized;
  InitializationStep step = map_initializer_.Step(*map_, frame, marker_fusion_.fix(), report.index);
  report.message = std::move(step.message);
  if (step.attempted) CountStat(&FrameFlowStats::num_initialization_attempts);
  if (step.for_backfill) lifecycle_.session().KeepForBackfill(*step.for_backfill);
  if (!step.map) return;
  if (step.map->in_world) {
    anchoring_.AlignedFromMarkers();  // re-aligned as anchors come
    marker_fusion_.MapEnteredWorld();
    lifecycle_.RefreshKeyframePoseCache(Parts());
    CountStat(&FrameFlowStats::num_marker_initializations);
  }
  FinishInitialization(*step.map, frame, report);
  if (step.map->in_world) report.message += " (from markers, in the world)";
}

void FrameFlow::FinishInitialization(const InitialMap& initial, Frame& frame,
                                     FrameReport& report) {
  const Frame& first = initial.first;
  const KeyframeId first_id = initial.first_id;
  const KeyframeId second_id = initial.second_id;
  tracker_->Start(frame, second_id);
  // The reference frame may have got a marker-only pose when it was seen: replaced in place.
  // Its own marker location goes with it, not the current frame's.
  pose_history_.Record(*map_, first, first_id, anchoring_.aligned(), initial.first_fix,
                       /*in_place=*/true);
  RecordPose(frame, second_id);
  lifecycle_.MapInitialized(Parts(), initial, frame);
  anchoring_.AddAnchor(first_id, initial.first_fix);
  anchoring_.AddAnchor(second_id, marker_fusion_.fix());
  marker_world_.MaybeAlign(MarkerParts(), frame);
  frames_since_keyframe_ = 0;
  last_state_ = TrackingState::kTracking;
  report.state = TrackingState::kTracking;
  report.cam_from_world = frame.cam_from_world;
  report.initialized_map = true;
  report.new_keyframe = true;
  report.num_inliers = initial.num_points;
  report.message = "map initialised with " + std::to_string(initial.num_points) + " points";
  std::lock_guard lock(*stats_mutex_);
  ++stats_->num_initializations;
  stats_->num_keyframes_inserted += 2;
}

void FrameFlow::Track(Frame& frame, FrameReport& report) {
  static const std::vector<MarkerPoseObservation> kNoMarkers;
  lifecycle_.FollowMapCorrections(Parts());
  const std::optional<MarkerFix>& fix = marker_fusion_.fix();
  TrackingResult result =
      tracker_->Track(frame, anchoring_.aligned() && fix ? fix->markers : kNoMarkers);
  if (result.state == TrackingState::kTracking && frame.cam_from_world &&
      marker_fusion_.JudgeTrackedPose(frame, anchoring_.aligned(), report.index) ==
          PoseVerdict::kRejected) {
    tracker_->MarkLost();
    frame.cam_from_world.reset();
    result.state = TrackingState::kLost;
  }
  if (result.state != TrackingState::kTracking &&
      (marker_world_.Relocalize(MarkerParts(), frame, report) ||
       lifecycle_.RelocalizeWithPlaces(Parts(), frame, report) ||
       lifecycle_.RelocalizeInLoadedMap(Parts(), frame, report))) {
    result.state = TrackingState::kTracking;
    result.num_inliers = report.num_inliers;
  }
  report.state = result.state;
  report.num_inliers = result.num_inliers;
  if (result.state != TrackingState::kTracking) {
    if (last_state_ == TrackingState::kTracking) CountStat(&FrameFlowStats::num_losses);
    last_state_ = result.state;
    report.message = "tracking lost";
    ARUCOSLAM_LOG_DEBUG("frame {}: tracking lost ({} keyframes in the map)", report.index,
                        map_->NumKeyframes());
    HandleLostFrame(frame, report.index);
    return;
  }
  last_state_ = TrackingState::kTracking;
  lifecycle_.session().OnTrackedFrame();
  marker_fusion_.NoteTrackedFrame(frame, anchoring_.aligned());
  ++frames_since_keyframe_;
  MaybeInsertKeyframe(frame, result.num_inliers, report);
  report.cam_from_world = frame.cam_from_world;
  RecordPose(frame, tracker_->reference_keyframe());
}

void FrameFlow::MaybeInsertKeyframe(Frame& frame, int num_inliers, FrameReport& report) {
  if (localize_only()) return;
  KeyframeDecisionInput input;
  input.frames_since_last_keyframe = frames_since_keyframe_;
  input.num_tracked = num_inliers;
  const int min_observations =
      map_->NumKeyframes() <= 2 ? 2 : options_.keyframes.min_observations;
  input.num_reference_tracked = map_->Read([&](const MapData& data) {
    return ReferenceTrackedPoints(data, tracker_->reference_keyframe(), min_observations);
  });
  input.mapper_idle = mapping_->Idle();
  input.mapper_has_room = mapping_->HasRoom();
  // A live source's young map takes a keyframe only from an idle mapper (tracking never waits).
  if (options_.live_source && MapIsYoung()) input.mapper_has_room = input.mapper_idle;
  // A frame with a usable marker location becomes a keyframe sooner until the map is first
  // aligned (anchors are kept on keyframes only).
  const bool wants_anchor =
      marker_fusion_.fix() && !anchoring_.aligned() &&
      frames_since_keyframe_ >= options_.min_frames_between_anchor_keyframes &&
      num_inliers > options_.keyframes.min_tracked_points && input.mapper_has_room;
  if (!wants_anchor && !DecideKeyframe(options_.keyframes, input).insert) return;
  const KeyframeId keyframe = InsertKeyframe(*map_, frame, tracker_->reference_keyframe());
  tracker_->SetReferenceKeyframe(keyframe);
  frames_since_keyframe_ = 0;
  report.new_keyframe = true;
  CountStat(&FrameFlowStats::num_keyframes_inserted);
  // The marker location is stored before the keyframe is handed over: the mapping thread's
  // drift correction reads it.
  anchoring_.AddAnchor(keyframe, marker_fusion_.fix());
  if (mapping_->Submit(keyframe)) {
    const bool young = !options_.live_source && MapIsYoung();  // counting the new keyframe
    const bool unaligned =
        options_.marker_map && !anchoring_.aligned() && options_.synchronous_until_aligned;
    if (young || unaligned) mapping_->WaitUntilMapped();
  }
  marker_world_.MaybeAlign(MarkerParts(), frame);
}

void FrameFlow::RecordPose(const Frame& frame, KeyframeId reference) {
  pose_history_.Record(*map_, frame, reference, anchoring_.aligned(), marker_fusion_.fix());
}

LocalMappingResult FrameFlow::MapKeyframe(KeyframeId keyframe) {
  PlaceIndex* places = lifecycle_.places();
  std::unique_lock<std::mutex> edit;  // a loop being closed pauses local mapping
  if (places) edit = places->LockMapEdits();
  marker_mapping_.AddKeyframe(*map_, keyframe);
  marker_world_.CorrectDrift(*map_, keyframe, anchoring_, marker_mapping_, places);
  LocalMappingResult result = mapper_->ProcessKeyframe(keyframe);
  if (!options_.marker_map) CalibrateRadialDistortion();
  if (places) {
    edit.unlock();
    // Before a loop correction moves the map.
    if (options_.inline_mapping) pose_history_.ReanchorOrphans(*map_);
    places->KeyframeMapped(keyframe);
  }
  return result;
}

void FrameFlow::Finish() {
  if (PlaceIndex* places = lifecycle_.places()) places->Finish();
  if (marker_mapping_.AdjustsWholeMap()) {
    lifecycle_.AdjustWholeMapWithMarkers(*map_, marker_mapping_, "end of the run");
  } else {
    marker_mapping_.RefineMappedMarkers(*map_);
  }
  std::optional<MarkerRelocationCounts> relocated;
  if (marker_mapping_.has_mapper() && options_.relocate_marker_poses) {
    relocated = pose_history_.RelocateInMarkerMap(marker_mapping_.ToMarkerMap(), marker_fusion_);
  }
  int num_refined = 0;
  if (options_.refine_frame_poses) {
    FramePoseRefinement refinement{options_.tracker.marker_pose, options_.tracker.min_pose_inliers,
                                   options_.refine_min_inlier_fraction};
    refinement.optimization.keypoints = options_.tracker.pose;
    num_refined =
        pose_history_.RefineAgainstMap(*map_, PinholeIntrinsics::FromCamera(Camera()), refinement);
  }
  int num_inconsistent = 0;
  const std::vector<StampedPose> trajectory = CheckedTrajectory(&num_inconsistent);
  // Frames seen without a pose or a marker that a backfill or the end posed do not count.
  const int unposed_without_markers = pose_history_.CountUnposedWithoutMarkers(trajectory);
  if (num_inconsistent > 0) {
    ARUCOSLAM_LOG_DEBUG("{} frames left out of the trajectory: off their keyframes' path",
                        num_inconsistent);
  }
  std::lock_guard lock(*stats_mutex_);
  stats_->num_inconsistent_poses = num_inconsistent;
  stats_->num_unposed_without_markers = unposed_without_markers;
  if (relocated) {
    stats_->num_relocated_marker_poses = relocated->num_relocated;
    stats_->num_late_marker_poses = relocated->num_late;
  }
  if (options_.refine_frame_poses) stats_->num_refined_frame_poses = num_refined;
}

std::vector<StampedPose> FrameFlow::CheckedTrajectory(int* num_dropped) const {
  if (num_dropped != nullptr) *num_dropped = 0;
  if (const std::vector<StampedPose>* closed =
          lifecycle_.session().BiggerClosedMapPoses(map_->NumKeyframes())) {
    return *closed;
  }
  std::vector<StampedPose> poses =
      pose_history_.CurrentMapPoses(*map_, /*world_only=*/options_.marker_map.has_value());
  // A loaded map's keyframes were timed in another run: they do not bracket these frames.
  if (!options_.drop_inconsistent_poses || lifecycle_.map_loaded()) return poses;
  return DropPosesOffTheirKeyframes(poses, KeyframePoses(), options_.pose_consistency, num_dropped);
}

std::vector<StampedPose> FrameFlow::KeyframePoses() const {
  return lifecycle_.KeyframePoses(*map_, anchoring_.aligned());
}

std::vector<Eigen::Vector3d> FrameFlow::MapPoints() const {
  return lifecycle_.MapPoints(*map_, anchoring_.aligned());
}

}  // namespace arucoslam
