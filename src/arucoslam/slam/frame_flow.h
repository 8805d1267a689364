// FrameFlow: the synchronous SLAM of one camera, one frame at a time: initialisation,
// tracking and its relocalisation chain, keyframe decisions, world alignment and map sessions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "arucoslam/geometry/pose_consistency.h"
#include "arucoslam/map/map.h"
#include "arucoslam/slam/frame_report.h"
#include "arucoslam/slam/keyframe_policy.h"
#include "arucoslam/slam/loaded_map_relocalizer.h"
#include "arucoslam/slam/local_mapper.h"
#include "arucoslam/slam/map_initializer.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/online_marker_mapping.h"
#include "arucoslam/slam/place_index.h"
#include "arucoslam/slam/pose_history.h"
#include "arucoslam/slam/radial_calibration.h"
#include "arucoslam/slam/tracker.h"
#include "arucoslam/slam/world_anchoring.h"

namespace arucoslam {

struct FrameFlowOptions {
  MapInitializerOptions initialization;
  TrackerOptions tracker;
  KeyframePolicyOptions keyframes;
  LocalMapperOptions mapper;
  MapSessionOptions map_session;
  RadialCalibrationOptions radial_calibration;  // keypoint-only maps
  std::optional<MarkerMap> marker_map;  // the known markers; none: keypoints only
  MarkerFusionOptions marker_fusion;
  WorldAnchoringOptions world_anchoring;
  OnlineMarkerMappingOptions marker_mapping;
  // Frames tracked between two keyframes kept for their marker location before the alignment.
  int min_frames_between_anchor_keyframes = 1;
  // Threaded mapping: a keyframe is mapped before the next frame while the map has at most
  // this many keyframes, and (synchronous_until_aligned) until it is in the marker world.
  int synchronous_young_map_keyframes = 20;
  bool synchronous_until_aligned = false;
  bool inline_mapping = true;           // keyframes are mapped between frames (blocking mode)
  bool yield_bundle_adjustment = true;  // threaded: a local BA yields to a waiting keyframe
  bool relocate_marker_poses = true;    // at Finish, marker poses located in the final markers
  bool refine_frame_poses = true;       // at Finish, frame poses against the final map
  double refine_min_inlier_fraction = 0.5;
  bool drop_inconsistent_poses = true;  // Trajectory leaves out poses off their keyframes
  PoseConsistencyOptions pose_consistency;
};

// A new PlaceIndex for a map; null without a vocabulary.
using PlaceIndexFactory = std::function<std::unique_ptr<PlaceIndex>(Map& map)>;

// Thread safety: everything runs on the tracking thread but MapKeyframe, which the mapping
// thread calls (MappingControl) and which touches the map, the local mapper, the marker
// mapping and the places only.
class FrameFlow {
 public:
  // Counts go to `stats` under `stats_mutex`.
  FrameFlow(const CameraModel& camera, const FrameFlowOptions& options, MappingControl* mapping,
            PlaceIndexFactory make_places, FrameFlowStats* stats, std::mutex* stats_mutex);
  ~FrameFlow();
  FrameFlow(const FrameFlow&) = delete;
  FrameFlow& operator=(const FrameFlow&) = delete;

  // The calibration new frames take: the camera given, its radial distortion refined by
  // radial_calibration on keypoint-only maps (any thread).
  CameraModel Camera() const;
  // What the map tells marker location about the next frame.
  MapPrediction Prediction() const;
  // A frame whose markers were located (marker_fusion()): initialised, tracked or
  // relocalised, a keyframe decided, its pose recorded; `report` gets the outcome.
  void Process(Frame& frame, FrameReport& report);
  // Local mapping of a keyframe handed to MappingControl (mapping thread, or inline).
  LocalMappingResult MapKeyframe(KeyframeId keyframe);
  // Before the first frame: a saved map replaces the empty one (frame_flow_maps.cc).
  void StartFromMap(MapData map, bool world_aligned, bool localize_only);
  // At the end, with mapping stopped: the last adjustments and pose refinements.
  void Finish();

  // Trajectory, and how many poses drop_inconsistent_poses left out (null: not counted).
  std::vector<StampedPose> CheckedTrajectory(int* num_dropped) const;
  std::vector<StampedPose> KeyframePoses() const;
  std::vector<Eigen::Vector3d> MapPoints() const;
  const Map& map() const { return *map_; }
  TrackingState state() const { return tracker_->state(); }
  bool world_aligned() const { return anchoring_.aligned(); }
  bool localize_only() const { return localize_only_; }
  MarkerFusion& marker_fusion() { return marker_fusion_; }
  const MarkerFusion& marker_fusion() const { return marker_fusion_; }
  OnlineMarkerMapping& marker_mapping() { return marker_mapping_; }
  const OnlineMarkerMapping& marker_mapping() const { return marker_mapping_; }
  const WorldAnchoring& anchoring() const { return anchoring_; }
  const MapSession& map_session() const { return map_session_; }

 private:
  // Tracking and keyframes (frame_flow.cc).
  void Initialize(Frame& frame, FrameReport& report);
  void FinishInitialization(const InitialMap& initial, Frame& frame, FrameReport& report);
  void Track(Frame& frame, FrameReport& report);
  void MaybeInsertKeyframe(Frame& frame, int num_inliers, FrameReport& report);
  // A frame's tracked pose against its reference keyframe, added to pose_history_.
  void RecordPose(const Frame& frame, KeyframeId reference);
  void CountStat(int FrameFlowStats::*counter, int amount = 1);

  // Markers (frame_flow_markers.cc).
  bool RelocalizeWithMarkers(Frame& frame, FrameReport& report);
  // Aligns the map to the world when anchoring_ decides so; `frame` (the current one, its
  // pose in the map) is carried along.
  void MaybeAlignWorld(Frame& frame);
  void RecordMarkerPose(const Frame& frame, FrameReport& report);
  // marker_mapping_ wired to the map, the local mapper and the places on each world alignment.
  void StartMarkerMapping();
  // Bundle adjustment of the whole world-aligned map with every marker view (`when` is for
  // the log); mapping must be stopped and the places' edit lock free.
  void AdjustWholeMapWithMarkers(const char* when);
  // Mapping thread, after the keyframe's markers were mapped: the pose-graph correction when
  // they contradict its pose.
  void CorrectDriftWithMarkers(KeyframeId keyframe);
  // A new mapper_ for map_: marker-keyframe guard and the BA's yield to a waiting keyframe.
  void MakeLocalMapper();

  // Map sessions, places and map reuse (frame_flow_maps.cc).
  void LocalizeInLoadedMap(Frame& frame, FrameReport& report);
  bool RelocalizeInLoadedMap(Frame& frame, FrameReport& report);
  bool RelocalizeWithPlaces(Frame& frame, FrameReport& report);
  void MakePlaces();
  // After a loop correction or a drift correction: the tracker's last pose follows its
  // reference keyframe into the corrected map; poses of culled keyframes are re-anchored first.
  void FollowMapCorrections();
  // The map was moved as a whole: the keyframe poses the re-anchoring compares against.
  void RefreshKeyframePoseCache();
  // Held while the map is moved from outside (world alignment); empty without places.
  std::unique_lock<std::mutex> LockPlacesForMapMove();
  // A lost frame: the map is kept, or reset as map_session_ says.
  void HandleLostFrame(const Frame& frame, std::size_t frame_index);
  // Replaces the map by an empty one; the poses in the world stay, frozen.
  void ResetMap();
  // Before ResetMap discards the map: what must outlive it; true when kept whole for a merge.
  bool CloseMap();
  // Once the current map is in the world: the closed map joins it, with its frozen poses,
  // marker views, marker priors and place entries. True when it merged.
  bool MergeClosedMap();
  // Once the closed map is merged: the new map corrected across the tracking gap.
  void CorrectAcrossBridge();
  // map_session_'s held bridge priors to the marker mapper and the places.
  void HandOutBridgePriors();
  // The frames kept for the backfill, tracked from `second` back in time.
  void BackfillInitialization(const Frame& second, KeyframeId first_id, KeyframeId second_id);

  // Radial calibration (frame_flow_calibration.cc). Tracking thread: a refined calibration
  // reaches the frame (undistorted again when extracted before it) and the kept matches.
  void FollowCalibration(Frame& frame);
  // Mapping thread, keypoint-only maps: radial_calibration_'s attempt when due.
  void CalibrateRadialDistortion();

  CameraModel camera_;  // guarded by camera_mutex_: the mapping thread refines it
  mutable std::mutex camera_mutex_;
  CameraModel tracked_camera_;  // tracking thread: the calibration of the poses it recorded
  RadialCalibration radial_calibration_;
  FrameFlowOptions options_;
  MappingControl* mapping_;
  PlaceIndexFactory make_places_;
  FrameFlowStats* stats_;
  std::mutex* stats_mutex_;

  MapInitializer map_initializer_;
  std::unique_ptr<Map> map_;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<LocalMapper> mapper_;
  int frames_since_keyframe_ = 0;
  TrackingState last_state_ = TrackingState::kNotInitialized;
  PoseHistory pose_history_;  // every frame's pose
  // The current frame's marker location (fix()) and the state it is judged with.
  MarkerFusion marker_fusion_;
  // The anchors, alignment decisions and marker priors of the current map.
  WorldAnchoring anchoring_;
  // Lost maps: reset, closed, merged into the next map, the gap bridged; the backfill.
  MapSession map_session_;
  // Markers mapped in the world; only the mapping thread touches it while it runs and the map
  // is live.
  OnlineMarkerMapping marker_mapping_;
  bool map_loaded_ = false;  // started from a saved map (StartFromMap)
  bool localize_only_ = false;
  LoadedMapRelocalizer loaded_map_relocalizer_;  // without places only
  std::unique_ptr<PlaceIndex> places_;           // with a vocabulary only
  std::uint64_t seen_corrections_ = 0;
  int seen_marker_corrections_ = 0;  // anchoring_'s drift corrections FollowMapCorrections saw
};

}  // namespace arucoslam
