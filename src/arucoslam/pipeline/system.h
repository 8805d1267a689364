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
#include "arucoslam/map/map.h"
#include "arucoslam/pipeline/bounded_queue.h"
#include "arucoslam/pipeline/marker_frontend.h"
#include "arucoslam/pipeline/place_recognition.h"
#include "arucoslam/pipeline/system_options.h"
#include "arucoslam/pipeline/system_report.h"
#include "arucoslam/slam/keyframe_policy.h"
#include "arucoslam/slam/loaded_map_relocalizer.h"
#include "arucoslam/slam/local_mapper.h"
#include "arucoslam/slam/map_initializer.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/online_marker_mapping.h"
#include "arucoslam/slam/pose_history.h"
#include "arucoslam/slam/radial_calibration.h"
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
  void Initialize(Frame& frame, FrameReport& report);
  void Track(Frame& frame, FrameReport& report);
  // Marker handling (system_markers.cc): the frame's markers located by marker_frontend_ with
  // marker_fusion_, with a marker map only.
  void LocateWithMarkers(Frame& frame, const std::vector<MarkerDetection>& detections,
                         FrameReport& report);
  bool RelocalizeWithMarkers(Frame& frame, FrameReport& report);
  // Map reuse (system_map_reuse.cc): a frame before the first localisation in a loaded map,
  // and the keyframe-seeded relocalisation (loaded_map_relocalizer_).
  void LocalizeInLoadedMap(Frame& frame, FrameReport& report);
  bool RelocalizeInLoadedMap(Frame& frame, FrameReport& report);
  // Aligns the map to the world when anchoring_ decides so; `frame` (the current one, its
  // pose in the map) is carried along.
  void MaybeAlignWorld(Frame& frame);
  void RecordMarkerPose(const Frame& frame, FrameReport& report);
  // Place recognition (system_places.cc).
  void MakePlaceRecognition();
  bool RelocalizeWithPlaces(Frame& frame, FrameReport& report);
  // After a loop correction or global BA: the tracker's last pose follows its reference
  // keyframe into the corrected map; poses of culled keyframes are re-anchored first.
  void FollowMapCorrections();
  // The map was moved as a whole (world alignment): the keyframe poses that the
  // re-anchoring compares against are re-read.
  void RefreshKeyframePoseCache();
  // Held while the map is moved from outside (world alignment); empty without places.
  std::unique_lock<std::mutex> LockPlacesForMapMove();
  // Marker mapping (system_marker_mapping.cc): marker_mapping_ wired to the map, the local
  // mapper and the places. Start: on each world alignment, with the mapping thread stopped.
  void StartMarkerMapping();
  // Bundle adjustment of the whole world-aligned map with every marker view (`when` is for
  // the log); the mapping thread must be stopped and the places' edit lock free.
  void AdjustWholeMapWithMarkers(const char* when);
  // Mapping thread, after the keyframe's markers were mapped: the pose-graph correction when
  // they contradict its pose. True when the map moved.
  bool CorrectDriftWithMarkers(KeyframeId keyframe);
  void MaybeInsertKeyframe(Frame& frame, int num_inliers, FrameReport& report);
  void MapKeyframe(KeyframeId keyframe);
  // A frame's tracked pose against its reference keyframe, added to pose_history_.
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
  // The frames kept for the backfill, tracked from `second` back in time: each one tracked
  // gets a pose, in place of a marker-only pose of the same frame.
  void BackfillInitialization(const Frame& second, KeyframeId first_id, KeyframeId second_id);
  // The first map (map_initializer_'s) carried out: tracking starts from `frame`, both frames
  // get their poses and anchors, the backfill is tracked and the map may align to the world.
  void FinishInitialization(const InitialMap& initial, Frame& frame, FrameReport& report);
  // Trajectory, and how many poses drop_inconsistent_poses left out (null: not counted).
  std::vector<StampedPose> CheckedTrajectory(int* num_dropped) const;
  void StartMappingThread();
  void StopMappingThread();
  bool MapperIdle() const;

  CameraModel camera_;  // the calibration new frames take; the mapping thread refines it
  mutable std::mutex camera_mutex_;  // guards camera_
  CameraModel tracked_camera_;  // tracking thread: the calibration of the poses it recorded
  CameraModel CurrentCamera() const;
  // Tracking thread: a refined calibration reaches the frame (undistorted again when it was
  // extracted before) and the kept matches.
  void FollowCalibration(Frame& frame);
  // Mapping thread, keypoint-only maps: radial_calibration_'s attempt when due.
  void CalibrateRadialDistortion();
  RadialCalibration radial_calibration_;
  SystemOptions options_;
  OrbExtractor extractor_;
  MapInitializer map_initializer_;
  std::unique_ptr<Map> map_;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<LocalMapper> mapper_;
  std::size_t num_frames_ = 0;
  int frames_since_keyframe_ = 0;
  TrackingState last_state_ = TrackingState::kNotInitialized;
  PoseHistory pose_history_;  // every frame's pose
  std::optional<KeyframeId> pending_keyframe_;  // blocking mode: to map after tracking

  std::unique_ptr<MarkerFrontend> marker_frontend_;  // with a marker map only
  // The current frame's marker location (fix()) and the state it is judged with.
  MarkerFusion marker_fusion_;
  // The anchors, alignment decisions and marker priors of the current map.
  WorldAnchoring anchoring_;
  // With a marker map: keyframes anchoring_ keeps are not culled.
  void GuardMarkerKeyframes();
  // A new mapper_ for map_: marker-keyframe guard, and in threaded mode the BA's yield to a
  // waiting keyframe (yield_bundle_adjustment).
  void MakeLocalMapper();
  // Lost maps: reset, closed, merged into the next map, the gap bridged; the backfill.
  MapSession map_session_;
  // Markers mapped in the world; only the mapping thread touches it while it runs and the map
  // is live.
  OnlineMarkerMapping marker_mapping_;

  bool map_loaded_ = false;    // started from a saved map (StartFromMap)
  bool localize_only_ = false;
  LoadedMapRelocalizer loaded_map_relocalizer_;  // without places only
  std::unique_ptr<PlaceRecognition> places_;  // with a vocabulary only
  std::uint64_t seen_corrections_ = 0;
  int seen_marker_corrections_ = 0;  // anchoring_'s drift corrections FollowMapCorrections saw

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
