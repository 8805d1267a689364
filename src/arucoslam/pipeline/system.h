// System: the monocular SLAM pipeline behind one call per image: ORB extraction, map
// initialisation, tracking, keyframe insertion and local mapping, blocking or on two threads;
// with a known marker map also world anchoring, metric scale and marker relocalisation.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <atomic>
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
#include "arucoslam/pipeline/system_options.h"
#include "arucoslam/pipeline/system_report.h"
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
  // Threaded mode: keyframes queued or being mapped (MapperIdle), from StartMappingThread.
  std::atomic<int> keyframes_in_mapping_{0};
  bool finished_ = false;

  mutable std::mutex stats_mutex_;
  SystemStats stats_;
};

}  // namespace arucoslam
