// System: the monocular SLAM pipeline behind one call per image: ORB extraction, map
// initialisation, tracking, keyframe insertion and local mapping, blocking or on two threads;
// with a known marker map also world anchoring, metric scale and marker relocalisation.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <atomic>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "arucoslam/feature/orb_extractor.h"
#include "arucoslam/geometry/pose_consistency.h"
#include "arucoslam/map/map.h"
#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/detector_regions.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/optim/essential_graph.h"
#include "arucoslam/optim/marker_factors.h"
#include "arucoslam/pipeline/bounded_queue.h"
#include "arucoslam/pipeline/marker_detector_worker.h"
#include "arucoslam/pipeline/place_recognition.h"
#include "arucoslam/slam/initializer.h"
#include "arucoslam/slam/keyframe_policy.h"
#include "arucoslam/slam/local_mapper.h"
#include "arucoslam/slam/map_initialization.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/marker_mapper.h"
#include "arucoslam/slam/tracker.h"
#include "arucoslam/slam/world_anchoring.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {

struct SystemOptions {
  OrbExtractorOptions extractor;
  InitializerOptions initializer;
  InitialMapOptions initial_map;
  TrackerOptions tracker;
  KeyframePolicyOptions keyframes;
  LocalMapperOptions mapper;
  // true: each frame is tracked and its keyframe mapped in the caller's thread before
  // ProcessImage returns (deterministic). false: local mapping runs on its own thread.
  bool blocking = true;
  int mapper_queue_capacity = 3;  // keyframes waiting for the mapping thread
  // Threaded mode: a local BA ends after its current iteration (at least the mapper's
  // min_iterations_before_stop) once another keyframe waits in the queue, so a new view gets
  // its points mapped without waiting for the BAs of the keyframes before it (ORB-SLAM's
  // abort). Blocking mode: no keyframe waits.
  bool yield_bundle_adjustment = true;
  // Threaded mode: while the map holds at most this many keyframes, tracking waits until
  // each new keyframe is mapped before it takes the next frame, as in blocking mode: a young
  // map tracked ahead of its local BA drifts in scale. 0: tracking never waits.
  int synchronous_young_map_keyframes = 20;
  // With a marker map: tracking also waits for every keyframe of a map not yet aligned to the
  // marker world. Off by default: a live camera would lose the frames of every such wait.
  bool synchronous_until_aligned = false;
  // The initialisation reference frame is replaced when the current frame is more than this
  // many seconds later (a reference is also replaced when too few matches are left). Long
  // enough for a vehicle that starts from rest to build up parallax.
  double max_initialization_gap_s = 3.0;
  // What becomes of a map that lost tracking (reset, closed, merged into the next one, the
  // gap bridged) and how many frames a new map's backfill tracks (slam/map_session.h).
  MapSessionOptions map_session;

  // Known markers (markers.json). When set, markers are detected in every image and located
  // (LocateCamera): frames without a keypoint pose get the marker pose, the keypoint map is
  // aligned to the world (Sim3, metric scale), tracking restarts from marker poses, and
  // aligned frames are optimised with the markers' corners. Unset: keypoints only.
  std::optional<MarkerMap> marker_map;
  // The detector's defaults, but without the edge refit of 20-60 px markers' corners
  // (DetectorOptions::edge_refinement): its corners are the more accurate ones, yet the SLAM
  // with them was worse on most simulated routes (BENCHMARKS.md, "Marker corners refitted
  // from their edges").
  DetectorOptions detector = [] {
    DetectorOptions options;
    options.edge_refinement = false;
    return options;
  }();
  // Where each image's markers are searched: the whole image every full_scan_interval
  // frames and whenever the previous frame has no pose in the marker world, else around the
  // known (and mapped) markers projected with that pose and the previous frame's detections
  // (MarkerDetector::DetectInRegions, about 10x cheaper). Markers missing from marker_map
  // are found at the whole-image searches, then followed. full_scan_interval 1: always the
  // whole image.
  MarkerSearchOptions marker_search;
  // Each frame's marker location, its ambiguity, and the verdict on keypoint poses that
  // contradict it (drift to correct, or a look-alike place).
  MarkerFusionOptions marker_fusion;
  // At Finish, when markers were mapped: frames posed by markers are located again in the
  // final marker map, and frames that saw markers but got no pose are located in it.
  bool relocate_marker_poses = true;
  // The keyframes' marker locations: when the map is aligned (and realigned) to the marker
  // world, and when they correct its drift.
  WorldAnchoringOptions world_anchoring;
  // Until the first alignment, a frame with a usable marker location becomes a keyframe when
  // at least this many frames passed since the last keyframe.
  int min_frames_between_anchor_keyframes = 1;
  // Once the map is world-aligned, keyframes' marker observations join local BA and the
  // global BA after a loop (known markers fixed) and markers the map lacks are mapped
  // (system_marker_mapping.cc).
  bool markers_in_local_ba = true;
  bool map_unknown_markers = true;
  // A world-aligned map gets one bundle adjustment of all its keyframes and points with every
  // marker-corner observation (known markers fixed, mapped ones estimated, views of culled
  // keyframes kept) when it is closed after a loss and at Finish (corner weights:
  // MarkerMapperOptions). false: at Finish only the mapped markers are refined.
  bool whole_map_marker_adjustment = true;
  // Mapped markers seen by at least this many keyframes locate frames like known ones
  // (marker poses and relocalisation where the known map has no marker). 0: never.
  int min_locating_marker_keyframes = 3;
  MarkerMapperOptions marker_mapping;

  // Bag-of-words vocabulary. When set, keyframes enter a place database: lost tracking is
  // relocalised from it and, with places.loop_closing, loops are closed. Null: neither.
  std::shared_ptr<const Vocabulary> vocabulary;
  PlaceRecognitionOptions places;
  // Marker initialisation: when the initialisation reference and the current frame both
  // have a usable marker location with centres at least this far apart (metres), the
  // matches are triangulated with the markers' relative pose and the map starts in the world.
  double min_marker_init_baseline_m = 0.5;
  // ... and at least this median parallax of the triangulated points (degrees).
  double min_marker_init_parallax_deg = 1.0;
  // At Finish, after the last map adjustments, every frame tracked in the map is optimised
  // again (motion only) against the final positions of the map points it matched when it
  // was tracked, plus the known markers it saw, starting from its pose relative to its
  // reference keyframe: that offset was fixed before the map's later corrections. The new
  // pose is kept when at least refine_min_inlier_fraction of those matches (and at least the
  // tracker's min_pose_inliers) are still in the map and stay inliers.
  // Keeps each tracked frame's matches until Finish. false: frames keep their keyframe
  // offsets.
  bool refine_frame_poses = true;
  double refine_min_inlier_fraction = 0.5;
  // Trajectory leaves out the frames that lie far off the path between the keyframes around
  // them in time (pose_consistency.h). false: every tracked pose is output.
  bool drop_inconsistent_poses = true;
  PoseConsistencyOptions pose_consistency;

  bool Check(std::string* why = nullptr) const;
};

struct FrameReport {
  std::size_t index = 0;  // 0-based count of frames given to the System
  double timestamp_s = 0.0;
  TrackingState state = TrackingState::kNotInitialized;
  std::optional<Rigid3> cam_from_world;  // as estimated when the frame was tracked
  bool initialized_map = false;          // this frame completed map initialisation
  bool new_keyframe = false;
  int num_features = 0;
  int num_inliers = 0;
  std::string message;  // initialisation outcome or loss, for logs
  int num_markers = 0;        // known markers detected (marker map only)
  std::vector<MarkerDetection> markers;  // all markers detected in the image (ProcessImage)
  bool marker_pose = false;   // the pose comes from the markers alone
  bool world_aligned = false; // the keypoint map is in the marker world frame (metric)
  // The frame's usable marker location (marker map only), world_from_cam.
  std::optional<Rigid3> marker_world_from_cam;
  // The frame's pose as known now (world_from_cam), what the ROS node publishes and `run`
  // writes to online.tum: with a marker map only a pose in the marker world (aligned map or
  // marker pose), without one the pose in the map's own frame.
  std::optional<Rigid3> online_world_from_cam;
};

struct SystemStats {
  TimingStats extraction_ms;     // per frame
  TimingStats tracking_ms;       // per frame: initialisation or tracking + keyframe decision
                                 // (no extraction, no local mapping)
  TimingStats frame_ms;          // per frame, everything on the tracking thread
  TimingStats local_mapping_ms;  // per keyframe
  int num_frames = 0;
  int num_tracked = 0;           // frames with a pose
  int num_lost = 0;              // frames in state lost
  // With a marker map, at Finish: frames without a pose in the trajectory that saw no marker
  // either (facing a plain wall between markers): where more markers, not better tracking,
  // would help.
  int num_unposed_without_markers = 0;
  int num_losses = 0;            // transitions tracking -> lost
  int num_initialization_attempts = 0;
  int num_initializations = 0;
  int num_keyframes_inserted = 0;
  TimingStats marker_ms;          // per frame with a marker map: detection and location
  // Per frame with a marker map: what the frame waits for markers (detection runs during
  // extraction; the time from extraction's end until detections are ready) plus location.
  TimingStats marker_wait_ms;
  int num_full_marker_scans = 0;  // frames whose markers were searched in the whole image
  MarkerFusionStats marker_fusion;     // marker locations and verdicts on keypoint poses
  int num_relocated_marker_poses = 0;  // marker poses located again in the final marker map
  int num_late_marker_poses = 0;       // frames without a pose located in it at the end
  int num_marker_only_poses = 0;  // frames whose pose came from markers alone
  WorldAnchoringStats world_anchoring;  // alignments to the marker world, drift corrections
  int num_marker_relocalizations = 0;  // tracking restarted from a marker pose
  int num_map_relocalizations = 0;     // loaded map: restarted from a keyframe match
  PlaceRecognitionStats places;        // relocalisation and loops (with a vocabulary)
  int num_marker_initializations = 0;  // maps initialised from two marker locations
  MapSessionStats map_session;         // resets, closed maps, merges and bridged gaps
  int num_whole_map_marker_adjustments = 0;  // bundle adjustments of a whole map with markers
  int num_refined_frame_poses = 0;  // frames re-optimised against the final map at Finish
  int num_yielded_bundle_adjustments = 0;  // local BAs ended early for a waiting keyframe
  int num_inconsistent_poses = 0;   // frames left out of Trajectory (pose_consistency)
};

class System {
 public:
  System(const CameraModel& camera, const SystemOptions& options = {});
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // One 8-bit grey image (distorted, as captured). Timestamps must increase.
  FrameReport ProcessImage(const cv::Mat& grey, double timestamp_s);
  // The same from features already extracted (`undistorted` filled, camera set).
  FrameReport ProcessFrame(Frame frame);
  // The same with the image's marker detections (distorted pixels), used with a marker map.
  FrameReport ProcessFrame(Frame frame, const std::vector<MarkerDetection>& detections);
  // Map reuse (system_map_reuse.cc): before the first frame, replaces the empty map with a
  // saved one (`world_aligned`: in the marker world frame). No map is initialised over it:
  // frames get no pose until a relocalisation into it succeeds (from markers when aligned,
  // else from keyframe matches). `localize_only`: no keyframe, no mapping, no alignment and
  // no reset; the map's keyframes and points stay as loaded.
  void StartFromMap(MapData map, bool world_aligned, bool localize_only);
  bool localize_only() const { return localize_only_; }
  // Waits until every queued keyframe is mapped and stops the mapping thread. Called by
  // the destructor; ProcessImage may not be called after it.
  void Finish();

  // Every frame that got a pose, re-expressed relative to its reference keyframe's final
  // pose when that keyframe is still in the map, but those off their keyframes
  // (drop_inconsistent_poses; not checked with a loaded map or for the biggest closed map
  // of a keypoint run). With a marker map: only poses in the world (marker poses, aligned
  // maps, closed maps frozen). Keypoints only: the poses of the map with the most keyframes
  // (maps are in unrelated frames), as ORB-SLAM3 does.
  std::vector<StampedPose> Trajectory() const;
  // Keyframes (in time order) and points of the current map plus, with a marker map, of
  // closed aligned maps.
  std::vector<StampedPose> KeyframePoses() const;
  std::vector<Eigen::Vector3d> MapPoints() const;
  const Map& map() const { return *map_; }
  TrackingState state() const { return tracker_ ? tracker_->state() : TrackingState::kNotInitialized; }
  bool world_aligned() const { return anchoring_.aligned(); }
  // The known markers (fixed as in markers.json) and the ones mapped online (fixed: false).
  // Call after Finish. Empty without a marker map.
  MarkerMap MarkerMapOutput() const;
  // Copy of the statistics (the mapping thread adds to local_mapping_ms).
  SystemStats Stats() const;

 private:
  struct FrameMatch {  // a keypoint of a tracked frame and the map point it matched
    MapPointId point;
    Eigen::Vector2f pixel;  // undistorted
    float sigma_px = 1.0f;
  };
  struct TrackedPose {
    double timestamp_s = 0.0;
    KeyframeId reference;
    Rigid3 cam_from_reference;
    double reference_scale = 1.0;  // the reference's KeyframeScale when recorded (loops)
    Rigid3 cam_from_world;
    bool in_world = false;  // expressed in the marker world (kept across map resets)
    // Frozen with a closed map that may still be merged: its reference keyframe there.
    KeyframeId closed_reference;
    // What tracking matched in the frame (refine_frame_poses; emptied at Finish).
    std::vector<FrameMatch> matches;
    std::vector<MarkerPoseObservation> markers;  // known markers only
    // The frame's marker location while its map is not in the world: its pose if the map
    // never gets there.
    std::optional<Rigid3> marker_cam_from_world;
    // The markers a frame posed by markers saw (RelocateMarkerPoses).
    std::vector<MarkerObservation> seen_markers;
  };
  struct UnposedMarkerFrame {  // a frame that saw markers but got no pose
    double timestamp_s = 0.0;
    std::vector<MarkerObservation> markers;
  };

  void Initialize(Frame& frame, FrameReport& report);
  void Track(Frame& frame, FrameReport& report);
  // Marker handling (system_markers.cc): the frame's markers and their location
  // (marker_fusion_), with a marker map only.
  void LocateWithMarkers(Frame& frame, const std::vector<MarkerDetection>& detections,
                         FrameReport& report);
  bool RelocalizeWithMarkers(Frame& frame, FrameReport& report);
  // Finish, when markers were mapped: the frames posed by markers are located again in the
  // final marker map, and the frames that saw markers but got no pose are located in it
  // (system_marker_relocation.cc).
  void RelocateMarkerPoses();
  // Map reuse (system_map_reuse.cc): a frame before the first localisation in a loaded map,
  // and the keyframe-seeded relocalisation (brute-force matching against a few keyframes
  // per frame, pose-only optimisation, then TrackFromPose).
  void LocalizeInLoadedMap(Frame& frame, FrameReport& report);
  bool RelocalizeInLoadedMap(Frame& frame, FrameReport& report);
  std::optional<Rigid3> SeedPoseFromKeyframes(const Frame& frame);
  // Aligns the map to the world when anchoring_ decides so; `frame` (the current one, its
  // pose in the map) is carried along.
  void MaybeAlignWorld(Frame& frame);
  void RecordMarkerPose(const Frame& frame, FrameReport& report);
  // Place recognition (system_places.cc).
  void MakePlaceRecognition();
  bool RelocalizeWithPlaces(Frame& frame, FrameReport& report);
  // After a loop correction or global BA: the tracker's last pose follows its reference
  // keyframe into the corrected map. Also re-anchors poses whose reference keyframe was
  // culled to the keyframe nearest in time, so that later corrections move them too.
  void FollowMapCorrections();
  // A tracked pose from its reference keyframe's pose; the offset follows the scale changes
  // that loop corrections applied around the reference since the pose was recorded.
  Rigid3 PoseFromReference(const TrackedPose& pose, const Rigid3& reference_cam_from_world) const;
  double ReferenceScale(KeyframeId reference) const;
  void ReanchorOrphanPoses();
  // Finish: refine_frame_poses (system_frame_refinement.cc).
  void RefineFramePoses();
  // The map was moved as a whole (world alignment): the cached keyframe poses that
  // ReanchorOrphanPoses compares against are re-read.
  void RefreshKeyframePoseCache();
  // Held while the map is moved from outside (world alignment); empty without places.
  std::unique_lock<std::mutex> LockPlacesForMapMove();
  // Marker mapping (system_marker_mapping.cc). Start: on each world alignment, with the
  // mapping thread stopped. Feed: a keyframe's markers, before its local mapping. Reset:
  // after the map was replaced. Finish: final marker refinement.
  void StartMarkerMapping();
  void FeedMarkerMapping(KeyframeId keyframe);
  // Tracking thread, while no map is in the world: a frame posed by markers maps unknown
  // markers as a marker view (MarkerMapper::AddMarkerView).
  void FeedMarkerView(const Frame& frame);
  MarkerMapper& EnsureMarkerMapper();
  int ResetMarkerMapping();  // the closed map's marker generation (-1: no mapper)
  void FinishMarkerMapping();
  // Bundle adjustment of the whole world-aligned map with every marker view (`when` is for
  // the log); the mapping thread must be stopped and the places' edit lock free.
  void AdjustWholeMapWithMarkers(const char* when);
  void PublishLocatingMarkers();  // mapping thread, after a keyframe's markers were added
  // Mapping thread, after FeedMarkerMapping: the pose-graph correction when the keyframe's
  // markers contradict its pose (system_drift_correction.cc). True when the map moved.
  bool CorrectDriftWithMarkers(KeyframeId keyframe);
  std::shared_ptr<const MarkerMap> LocatingMarkers() const;
  void MaybeInsertKeyframe(Frame& frame, int num_inliers, FrameReport& report);
  void MapKeyframe(KeyframeId keyframe);
  // A frame's tracked pose against its reference keyframe, with what tracking matched in it
  // (refine_frame_poses), and the same added to poses_.
  TrackedPose MakeTrackedPose(const Frame& frame, KeyframeId reference) const;
  void RecordPose(const Frame& frame, KeyframeId reference);
  // Map sessions (system_map_session.cc): map_session_'s decisions carried out on the map,
  // the poses, the marker mapper and the place recognition.
  // A lost frame (`frame_index` for the log): the map is kept, or reset as map_session_ says.
  void HandleLostFrame(const Frame& frame, std::size_t frame_index);
  // Replaces the map by an empty one; the poses in the world stay, frozen (those of a map
  // kept for a merge remember their keyframe there).
  void ResetMap();
  // Before ResetMap discards the map: map_session_ keeps what must outlive it; true when the
  // map is kept whole for a merge.
  bool CloseMap();
  // Once the current map is in the world: the closed map joins it, with its frozen poses,
  // marker views, marker priors and place-database entries. Called with the mapping thread
  // stopped and the places' edit lock held. True when it merged.
  bool MergeClosedMap();
  // Once the closed map is merged: the new map corrected across the tracking gap.
  void CorrectAcrossBridge();
  // Hands map_session_'s held bridge priors to the marker mapper and the place recognition;
  // the caller holds the places' edit lock (LockPlacesForMapMove) or has just made them anew.
  void HandOutBridgePriors();
  // `frame` becomes the initialisation reference, with its marker location; the reference it
  // replaces is kept for the backfill.
  void ReplaceInitReference(const Frame& frame);
  // The frames kept for the backfill, tracked from `second` back in time: each one tracked
  // gets a pose, in place of a marker-only pose of the same frame.
  void BackfillInitialization(const Frame& second, KeyframeId first_id, KeyframeId second_id);
  // Marker initialisation (system_marker_initialization.cc): builds the initial map from the
  // marker poses of the reference and `frame` directly in the world; false when the marker
  // poses do not allow it (the caller initialises as usual).
  bool InitializeFromMarkers(Frame& frame, FrameReport& report);
  void FinishInitialization(Frame& first, Frame& frame, KeyframeId first_id,
                            KeyframeId second_id, int num_points, FrameReport& report);
  // Trajectory, and how many poses drop_inconsistent_poses left out (null: not counted).
  std::vector<StampedPose> CheckedTrajectory(int* num_dropped) const;
  // Poses of the current map in its own frame (reference keyframes' final poses).
  std::vector<StampedPose> CurrentMapPoses(bool world_only) const;
  void StartMappingThread();
  void StopMappingThread();
  bool MapperIdle() const;

  CameraModel camera_;
  SystemOptions options_;
  OrbExtractor extractor_;
  Initializer initializer_;
  std::unique_ptr<Map> map_;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<LocalMapper> mapper_;
  std::optional<Frame> init_reference_;
  std::size_t num_frames_ = 0;
  int frames_since_keyframe_ = 0;
  TrackingState last_state_ = TrackingState::kNotInitialized;
  std::vector<TrackedPose> poses_;
  std::optional<KeyframeId> pending_keyframe_;  // blocking mode: to map after tracking

  std::unique_ptr<MarkerDetector> detector_;  // with a marker map only
  std::unique_ptr<MarkerDetectorWorker> detector_worker_;  // runs detector_, with it
  std::unique_ptr<MarkerSearchPlanner> marker_search_;     // with detector_
  // Where the current image's markers are searched (nullopt: the whole image), and after
  // the frame, what the next one's search needs (system_marker_search.cc).
  std::optional<std::vector<cv::Rect>> MarkerSearchRegions();
  void RememberMarkerView(const FrameReport& report,
                          const std::vector<MarkerDetection>& detections);
  // The current frame's marker location (fix()) and the state it is judged with.
  MarkerFusion marker_fusion_;
  std::optional<MarkerFix> init_reference_fix_;
  // The anchors, alignment decisions and marker priors of the current map.
  WorldAnchoring anchoring_;
  // With a marker map: keyframes anchoring_ keeps are not culled.
  void GuardMarkerKeyframes();
  // A new mapper_ for map_: marker-keyframe guard, and in threaded mode the BA's yield to a
  // waiting keyframe (yield_bundle_adjustment).
  void MakeLocalMapper();
  // Lost maps: reset, closed, merged into the next map, the gap bridged; the backfill.
  MapSession map_session_;
  double detection_ms_ = 0.0;  // marker detection time of the current image
  double marker_wait_ms_ = 0.0;  // the current image's wait for its detections
  // Markers of the world-aligned map; only the mapping thread touches it while it runs.
  std::unique_ptr<MarkerMapper> marker_mapper_;
  std::vector<UnposedMarkerFrame> unposed_marker_frames_;
  std::vector<double> unposed_without_markers_s_;  // frames seen without pose nor marker
  int marker_views_refined_ = 0;  // marker views at the last refinement (FeedMarkerView)
  bool marker_mapping_live_ = false;  // the current map is aligned and feeds marker_mapper_
  // Known + mapped markers that locate frames, published by the mapping thread.
  mutable std::mutex locating_mutex_;
  std::shared_ptr<const MarkerMap> locating_markers_;

  bool map_loaded_ = false;    // started from a saved map (StartFromMap)
  bool localize_only_ = false;
  std::size_t next_seed_keyframe_ = 0;  // round-robin position of SeedPoseFromKeyframes
  std::unique_ptr<PlaceRecognition> places_;  // with a vocabulary only
  std::uint64_t seen_corrections_ = 0;
  int seen_marker_corrections_ = 0;  // anchoring_'s drift corrections FollowMapCorrections saw
  std::map<KeyframeId, Rigid3> keyframe_poses_;  // as of the previous frame (re-anchoring)

  std::unique_ptr<BoundedQueue<KeyframeId>> queue_;
  std::thread mapping_thread_;
  std::atomic<bool> mapping_busy_{false};
  // Threaded mode: keyframes pushed to queue_ and keyframes the mapping thread finished,
  // both counted from StartMappingThread (synchronous_young_map_keyframes).
  std::size_t keyframes_queued_ = 0;
  std::size_t keyframes_mapped_ = 0;  // guarded by mapped_mutex_
  std::mutex mapped_mutex_;
  std::condition_variable mapped_;
  // Waits until the mapping thread has mapped every keyframe queued so far.
  void WaitForMapping();
  bool finished_ = false;

  mutable std::mutex stats_mutex_;
  SystemStats stats_;
};

}  // namespace arucoslam
