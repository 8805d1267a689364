#include "arucoslam/pipeline/system.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "arucoslam/feature/undistort.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {
namespace {

MarkerFusion MakeMarkerFusion(const SystemOptions& options, const CameraModel& camera) {
  if (!options.marker_map) return MarkerFusion(options.marker_fusion, camera, MarkerMap(), 0.0);
  const double unknown_size =
      UnknownMarkerSize(*options.marker_map, options.marker_mapping.unknown_marker_size_m);
  return MarkerFusion(options.marker_fusion, camera, *options.marker_map, unknown_size);
}

OnlineMarkerMappingOptions MakeMarkerMappingOptions(const SystemOptions& options) {
  OnlineMarkerMappingOptions mapping;
  mapping.mapper = options.marker_mapping;
  mapping.map_unknown_markers = options.map_unknown_markers;
  mapping.markers_in_local_ba = options.markers_in_local_ba;
  mapping.whole_map_adjustment = options.whole_map_marker_adjustment;
  mapping.min_locating_keyframes = options.min_locating_marker_keyframes;
  return mapping;
}

MapInitializerOptions MakeMapInitializerOptions(const SystemOptions& options) {
  MapInitializerOptions initialization;
  initialization.two_view = options.initializer;
  initialization.initial_map = options.initial_map;
  initialization.max_reference_gap_s = options.max_initialization_gap_s;
  initialization.markers.min_baseline_m = options.min_marker_init_baseline_m;
  initialization.markers.min_parallax_deg = options.min_marker_init_parallax_deg;
  initialization.markers.alignment = options.world_anchoring.alignment;
  return initialization;
}

}  // namespace

System::System(const CameraModel& camera, const SystemOptions& options)
    : camera_(camera),
      tracked_camera_(camera),
      radial_calibration_(options.radial_calibration),
      options_(options),
      extractor_(options.extractor),
      map_initializer_(camera, MakeMapInitializerOptions(options)),
      pose_history_(options.refine_frame_poses,
                    [this](KeyframeId id) { return places_ ? places_->KeyframeScale(id) : 1.0; }),
      marker_fusion_(MakeMarkerFusion(options, camera)),
      anchoring_(options.world_anchoring),
      map_session_(options.map_session, options.marker_map.has_value()),
      marker_mapping_(options.marker_map, MakeMarkerMappingOptions(options)),
      loaded_map_relocalizer_(options.tracker) {
  if (std::string why; !options_.Check(&why)) {
    throw std::invalid_argument("System: invalid SystemOptions: " + why);
  }
  map_ = std::make_unique<Map>();
  tracker_ = std::make_unique<Tracker>(*map_, options_.tracker);
  MakeLocalMapper();
  if (options_.marker_map) {
    marker_frontend_ =
        std::make_unique<MarkerFrontend>(camera_, options_.detector, options_.marker_search);
  }
  MakePlaceRecognition();
  StartMappingThread();
}

System::~System() { Finish(); }

void System::StartMappingThread() {
  if (options_.blocking) return;
  queue_ = std::make_unique<BoundedQueue<KeyframeId>>(options_.mapper_queue_capacity);
  keyframes_queued_ = 0;
  {
    std::lock_guard lock(mapped_mutex_);
    keyframes_mapped_ = 0;
  }
  mapping_thread_ = std::thread([this] {
    while (const std::optional<KeyframeId> keyframe = queue_->Pop()) {
      MapKeyframe(*keyframe);
      mapping_busy_ = false;
      {
        std::lock_guard lock(mapped_mutex_);
        ++keyframes_mapped_;
      }
      mapped_.notify_all();
    }
  });
}

void System::StopMappingThread() {
  if (!mapping_thread_.joinable()) return;
  queue_->Close();
  mapping_thread_.join();
}

void System::Finish() {
  if (finished_) return;
  finished_ = true;
  StopMappingThread();
  if (places_) places_->Finish();
  if (marker_mapping_.AdjustsWholeMap()) {
    AdjustWholeMapWithMarkers("end of the run");
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
        pose_history_.RefineAgainstMap(*map_, PinholeIntrinsics::FromCamera(camera_), refinement);
  }
  int num_inconsistent = 0;
  const std::vector<StampedPose> trajectory = CheckedTrajectory(&num_inconsistent);
  // Frames seen without a pose or a marker that a backfill or the end posed do not count.
  const int unposed_without_markers = pose_history_.CountUnposedWithoutMarkers(trajectory);
  if (num_inconsistent > 0) {
    ARUCOSLAM_LOG_DEBUG("{} frames left out of the trajectory: off their keyframes' path",
                        num_inconsistent);
  }
  std::lock_guard lock(stats_mutex_);
  stats_.num_inconsistent_poses = num_inconsistent;
  stats_.num_unposed_without_markers = unposed_without_markers;
  if (relocated) {
    stats_.num_relocated_marker_poses = relocated->num_relocated;
    stats_.num_late_marker_poses = relocated->num_late;
  }
  if (options_.refine_frame_poses) stats_.num_refined_frame_poses = num_refined;
}

void System::WaitForMapping() {
  std::unique_lock lock(mapped_mutex_);
  mapped_.wait(lock, [this] { return keyframes_mapped_ >= keyframes_queued_; });
}

void System::MakeLocalMapper() {
  mapper_ = std::make_unique<LocalMapper>(*map_, options_.mapper);
  GuardMarkerKeyframes();
  if (!options_.blocking && options_.yield_bundle_adjustment) {
    // queue_ is replaced only while the mapping thread is stopped.
    mapper_->SetYieldRequest([this] { return queue_ && queue_->Size() > 0; });
  }
}

bool System::MapperIdle() const {
  if (options_.blocking) return true;
  return !mapping_busy_ && queue_->Size() == 0;
}

void System::MapKeyframe(KeyframeId keyframe) {
  const Stopwatch watch;
  std::unique_lock<std::mutex> edit;  // a loop being closed pauses local mapping
  if (places_) edit = places_->LockMapEdits();
  marker_mapping_.AddKeyframe(*map_, keyframe);
  CorrectDriftWithMarkers(keyframe);
  const LocalMappingResult r = mapper_->ProcessKeyframe(keyframe);
  if (!options_.marker_map) CalibrateRadialDistortion();
  const bool yielded = r.bundle_adjustment.summary.stopped_early;
  const double elapsed = watch.ElapsedMilliseconds();
  if (places_) {
    edit.unlock();
    // Before a loop correction moves the map.
    if (options_.blocking) pose_history_.ReanchorOrphans(*map_);
    places_->KeyframeMapped(keyframe);
  }
  ARUCOSLAM_LOG_DEBUG(
      "keyframe {}: {} culled, {} new ({:.0f} ms), {} fused ({:.0f} ms), BA {} kf {} pts "
      "rms {:.2f}->{:.2f} px{}, {} outliers ({:.0f} ms), {} keyframes culled; {:.0f} ms",
      keyframe.value, r.num_culled_points, r.num_new_points, r.triangulation_ms, r.num_fused_points,
      r.fusion_ms, r.bundle_adjustment.num_local_keyframes, r.bundle_adjustment.num_points,
      r.bundle_adjustment.summary.initial_rms_px, r.bundle_adjustment.summary.final_rms_px,
      yielded ? fmt::format(" (yielded after {} iterations)",
                            r.bundle_adjustment.summary.num_iterations)
              : std::string(),
      r.bundle_adjustment.num_erased_observations, r.bundle_adjustment_ms, r.num_culled_keyframes,
      elapsed);
  std::lock_guard lock(stats_mutex_);
  stats_.local_mapping_ms.Add(elapsed);
  if (yielded) ++stats_.num_yielded_bundle_adjustments;
}

CameraModel System::CurrentCamera() const {
  std::lock_guard lock(camera_mutex_);
  return camera_;
}

namespace {
bool SameDistortion(const CameraModel& a, const CameraModel& b) {
  return a.model == b.model && a.distortion == b.distortion;
}
}  // namespace

void System::FollowCalibration(Frame& frame) {
  const CameraModel camera = CurrentCamera();
  if (!SameDistortion(camera, tracked_camera_)) {
    pose_history_.Recalibrate(tracked_camera_, camera);
    tracked_camera_ = camera;
  }
  if (!SameDistortion(frame.camera, camera) && frame.camera.fx == camera.fx &&
      frame.camera.cx == camera.cx) {
    frame.camera = camera;
    UndistortFeatures(camera, &frame.features);
  }
}

void System::CalibrateRadialDistortion() {
  CameraModel camera = CurrentCamera();
  const RadialCalibrationStep step = radial_calibration_.MaybeRefine(*map_, &camera);
  if (!step.attempted) return;
  ARUCOSLAM_LOG_INFO("radial calibration at {} keyframes: k {:+.4f}, cost {:.1f} -> {:.1f} ({})",
                     map_->NumKeyframes(), step.k, step.cost_without, step.cost_with, step.message);
  if (!step.applied) return;
  {
    std::lock_guard lock(camera_mutex_);
    camera_ = camera;
  }
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_radial_calibrations;
  stats_.radial_k1_correction += step.k;
}

FrameReport System::ProcessImage(const cv::Mat& grey, double timestamp_s) {
  const Stopwatch watch;
  Frame frame;
  frame.id = FrameId(num_frames_);
  frame.timestamp_s = timestamp_s;
  frame.camera = CurrentCamera();
  // Marker detection runs on the worker's thread meanwhile; the frame waits only for what
  // is left of it after extraction.
  if (marker_frontend_) marker_frontend_->StartDetection(grey, *marker_mapping_.LocatingMarkers());
  try {
    frame.features = extractor_.Extract(grey);
  } catch (...) {
    if (marker_frontend_) marker_frontend_->AbandonDetection();
    throw;
  }
  UndistortFeatures(frame.camera, &frame.features);
  frame.ResetMatches();
  const double extraction = watch.ElapsedMilliseconds();
  std::vector<MarkerDetection> detections;
  if (marker_frontend_) detections = marker_frontend_->WaitForDetections();
  FrameReport report = ProcessFrame(std::move(frame), detections);
  if (marker_frontend_) marker_frontend_->RememberFrame(report, marker_fusion_.fix(), detections);
  report.markers = std::move(detections);
  std::lock_guard lock(stats_mutex_);
  stats_.extraction_ms.Add(extraction);
  stats_.frame_ms.Add(watch.ElapsedMilliseconds());
  return report;
}

FrameReport System::ProcessFrame(Frame frame) { return ProcessFrame(std::move(frame), {}); }

FrameReport System::ProcessFrame(Frame frame, const std::vector<MarkerDetection>& detections) {
  if (finished_) throw std::logic_error("System::ProcessFrame after Finish");
  const Stopwatch watch;
  FrameReport report;
  report.index = num_frames_++;
  report.timestamp_s = frame.timestamp_s;
  report.num_features = static_cast<int>(frame.features.size());
  if (frame.map_point_ids.size() != frame.features.size()) frame.ResetMatches();
  FollowCalibration(frame);
  LocateWithMarkers(frame, detections, report);
  const std::optional<MarkerFix>& fix = marker_fusion_.fix();
  if (tracker_->state() == TrackingState::kNotInitialized) {
    map_loaded_ ? LocalizeInLoadedMap(frame, report) : Initialize(frame, report);
  } else {
    Track(frame, report);
  }
  // A loaded map that stays outside the marker world takes no marker-only poses.
  const bool marker_poses = anchoring_.aligned() || !localize_only_;
  if (!report.cam_from_world && fix && marker_poses) RecordMarkerPose(frame, report);
  if (!localize_only_) marker_mapping_.AddMarkerView(frame, marker_fusion_.fix());
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
  {
    std::lock_guard lock(stats_mutex_);
    ++stats_.num_frames;
    if (report.cam_from_world) ++stats_.num_tracked;
    if (report.state == TrackingState::kLost) ++stats_.num_lost;
    if (options_.marker_map && !report.cam_from_world && frame.markers.empty()) {
      pose_history_.NoteUnposedWithoutMarkers(frame.timestamp_s);
    }
    stats_.tracking_ms.Add(watch.ElapsedMilliseconds());
    stats_.marker_fusion = marker_fusion_.stats();
    stats_.map_session = map_session_.stats();
  }
  if (pending_keyframe_) {
    MapKeyframe(*pending_keyframe_);
    pending_keyframe_.reset();
  }
  return report;
}

void System::Initialize(Frame& frame, FrameReport& report) {
  report.state = TrackingState::kNotInitialized;
  InitializationStep step = map_initializer_.Step(*map_, frame, marker_fusion_.fix(), report.index);
  report.message = std::move(step.message);
  if (step.attempted) {
    std::lock_guard lock(stats_mutex_);
    ++stats_.num_initialization_attempts;
  }
  if (step.for_backfill) map_session_.KeepForBackfill(*step.for_backfill);
  if (!step.map) return;
  if (step.map->in_world) {
    anchoring_.AlignedFromMarkers();  // re-aligned as anchors come
    marker_fusion_.MapEnteredWorld(frame.timestamp_s);
    RefreshKeyframePoseCache();
    std::lock_guard lock(stats_mutex_);
    ++stats_.num_marker_initializations;
  }
  FinishInitialization(*step.map, frame, report);
  if (step.map->in_world) report.message += " (from markers, in the world)";
}

void System::FinishInitialization(const InitialMap& initial, Frame& frame, FrameReport& report) {
  const Frame& first = initial.first;
  const KeyframeId first_id = initial.first_id;
  const KeyframeId second_id = initial.second_id;
  tracker_->Start(frame, second_id);
  // The reference frame may have got a marker-only pose when it was seen: replaced in place.
  // Its own marker location goes with it, not the current frame's.
  pose_history_.Record(*map_, first, first_id, anchoring_.aligned(), initial.first_fix,
                       /*in_place=*/true);
  RecordPose(frame, second_id);
  BackfillInitialization(frame, first_id, second_id);
  if (places_) {
    places_->KeyframeMapped(first_id);
    places_->KeyframeMapped(second_id);
  }
  map_session_.AddBridgePrior(first_id, first.timestamp_s, anchoring_.aligned());
  anchoring_.AddAnchor(first_id, initial.first_fix);
  anchoring_.AddAnchor(second_id, marker_fusion_.fix());
  MaybeAlignWorld(frame);
  frames_since_keyframe_ = 0;
  last_state_ = TrackingState::kTracking;
  report.state = TrackingState::kTracking;
  report.cam_from_world = frame.cam_from_world;
  report.initialized_map = true;
  report.new_keyframe = true;
  report.num_inliers = initial.num_points;
  report.message = "map initialised with " + std::to_string(initial.num_points) + " points";
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_initializations;
  stats_.num_keyframes_inserted += 2;
}

void System::Track(Frame& frame, FrameReport& report) {
  static const std::vector<MarkerPoseObservation> kNoMarkers;
  FollowMapCorrections();
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
  bool relocalized = false;
  if (result.state != TrackingState::kTracking &&
      (RelocalizeWithMarkers(frame, report) || RelocalizeWithPlaces(frame, report) ||
       RelocalizeInLoadedMap(frame, report))) {
    result.state = TrackingState::kTracking;
    result.num_inliers = report.num_inliers;
    relocalized = true;
  }
  report.state = result.state;
  report.num_inliers = result.num_inliers;
  if (result.state != TrackingState::kTracking) {
    if (last_state_ == TrackingState::kTracking) {
      std::lock_guard lock(stats_mutex_);
      ++stats_.num_losses;
    }
    last_state_ = result.state;
    report.message = "tracking lost";
    ARUCOSLAM_LOG_DEBUG("frame {}: tracking lost ({} keyframes in the map)", report.index,
                        map_->NumKeyframes());
    HandleLostFrame(frame, report.index);
    return;
  }
  last_state_ = TrackingState::kTracking;
  map_session_.OnTrackedFrame();
  marker_fusion_.NoteTrackedFrame(frame, relocalized, anchoring_.aligned());
  ++frames_since_keyframe_;
  MaybeInsertKeyframe(frame, result.num_inliers, report);
  report.cam_from_world = frame.cam_from_world;
  RecordPose(frame, tracker_->reference_keyframe());
}

void System::MaybeInsertKeyframe(Frame& frame, int num_inliers, FrameReport& report) {
  if (localize_only_) return;
  KeyframeDecisionInput input;
  input.frames_since_last_keyframe = frames_since_keyframe_;
  input.num_tracked = num_inliers;
  const int min_observations =
      map_->NumKeyframes() <= 2 ? 2 : options_.keyframes.min_observations;
  input.num_reference_tracked = map_->Read([&](const MapData& data) {
    return ReferenceTrackedPoints(data, tracker_->reference_keyframe(), min_observations);
  });
  input.mapper_idle = MapperIdle();
  input.mapper_has_room = options_.blocking || queue_->Size() < queue_->capacity();
  // A frame with a usable marker location becomes a keyframe sooner until the map is first
  // aligned (anchors are kept on keyframes only).
  const bool wants_anchor =
      marker_fusion_.fix() && !anchoring_.aligned() &&
      frames_since_keyframe_ >= options_.min_frames_between_anchor_keyframes &&
      num_inliers > options_.keyframes.min_tracked_points && input.mapper_has_room;
  const bool wants_drift_keyframe = marker_fusion_.drift_keyframe_wanted() && input.mapper_has_room;
  if (!wants_anchor && !wants_drift_keyframe && !DecideKeyframe(options_.keyframes, input).insert) {
    return;
  }
  marker_fusion_.KeyframeInserted();
  const KeyframeId keyframe = InsertKeyframe(*map_, frame, tracker_->reference_keyframe());
  tracker_->SetReferenceKeyframe(keyframe);
  frames_since_keyframe_ = 0;
  report.new_keyframe = true;
  {
    std::lock_guard lock(stats_mutex_);
    ++stats_.num_keyframes_inserted;
  }
  // The marker location is stored before the keyframe is queued: the mapping thread's drift
  // correction reads it.
  anchoring_.AddAnchor(keyframe, marker_fusion_.fix());
  if (options_.blocking) {
    pending_keyframe_ = keyframe;  // mapped once the frame's tracking time is recorded
  } else {
    mapping_busy_ = true;
    if (queue_->Push(keyframe)) {
      ++keyframes_queued_;
      const bool young =
          static_cast<int>(map_->NumKeyframes()) <= options_.synchronous_young_map_keyframes;
      const bool unaligned =
          options_.marker_map && !anchoring_.aligned() && options_.synchronous_until_aligned;
      if (young || unaligned) {
        WaitForMapping();
      }
    }
  }
  MaybeAlignWorld(frame);
}

void System::RecordPose(const Frame& frame, KeyframeId reference) {
  pose_history_.Record(*map_, frame, reference, anchoring_.aligned(), marker_fusion_.fix());
}

std::vector<StampedPose> System::Trajectory() const { return CheckedTrajectory(nullptr); }

std::vector<StampedPose> System::CheckedTrajectory(int* num_dropped) const {
  if (num_dropped != nullptr) *num_dropped = 0;
  if (const std::vector<StampedPose>* closed =
          map_session_.BiggerClosedMapPoses(map_->NumKeyframes())) {
    return *closed;
  }
  std::vector<StampedPose> poses =
      pose_history_.CurrentMapPoses(*map_, /*world_only=*/options_.marker_map.has_value());
  // A loaded map's keyframes were timed in another run: they do not bracket these frames.
  if (!options_.drop_inconsistent_poses || map_loaded_) return poses;
  return DropPosesOffTheirKeyframes(poses, KeyframePoses(), options_.pose_consistency, num_dropped);
}

std::vector<StampedPose> System::KeyframePoses() const {
  std::vector<StampedPose> poses = map_session_.closed_keyframes();
  if (!options_.marker_map || anchoring_.aligned()) {  // else the map is not in the world frame
    map_->Read([&](const MapData& data) {
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

std::vector<Eigen::Vector3d> System::MapPoints() const {
  std::vector<Eigen::Vector3d> points = map_session_.closed_points();
  if (options_.marker_map && !anchoring_.aligned()) return points;  // not in the world frame
  map_->Read([&](const MapData& data) {
    for (const auto& [id, point] : data.map_points()) points.push_back(point.p_in_world);
    return 0;
  });
  return points;
}

SystemStats System::Stats() const {
  std::lock_guard lock(stats_mutex_);
  SystemStats stats = stats_;
  stats.world_anchoring = anchoring_.stats();
  stats.num_whole_map_marker_adjustments = marker_mapping_.stats().num_whole_map_adjustments;
  if (marker_frontend_) {
    MarkerFrontendStats markers = marker_frontend_->stats();
    stats.marker_ms = std::move(markers.marker_ms);
    stats.marker_wait_ms = std::move(markers.wait_ms);
    stats.num_full_marker_scans = markers.num_full_scans;
  }
  return stats;
}

}  // namespace arucoslam
