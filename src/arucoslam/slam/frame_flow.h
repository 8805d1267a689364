// FrameFlow: the synchronous SLAM of one camera, one frame at a time: initialisation,
// tracking and its relocalisation chain, keyframe decisions; the marker world is MarkerWorld's,
// the maps one after the other MapLifecycle's.
#pragma once

#include <cstddef>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "arucoslam/map/map.h"
#include "arucoslam/slam/frame_flow_options.h"
#include "arucoslam/slam/frame_report.h"
#include "arucoslam/slam/local_mapper.h"
#include "arucoslam/slam/map_initializer.h"
#include "arucoslam/slam/map_lifecycle.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/marker_world.h"
#include "arucoslam/slam/online_marker_mapping.h"
#include "arucoslam/slam/pose_history.h"
#include "arucoslam/slam/radial_calibration.h"
#include "arucoslam/slam/tracker.h"
#include "arucoslam/slam/world_anchoring.h"

namespace arucoslam {

// Thread safety: everything runs on the tracking thread but MapKeyframe, which the mapping
// thread calls (MappingControl) and which touches the map, the local mapper, the marker
// mapping and the places only.
class FrameFlow {
 public:
  // Counts go to `stats` under `stats_mutex`. Invalid options: std::invalid_argument naming
  // the field.
  FrameFlow(const CameraModel& camera, const FrameFlowOptions& options, MappingControl* mapping,
            PlaceIndexFactory make_places, FrameFlowStats* stats, std::mutex* stats_mutex);
  ~FrameFlow();
  FrameFlow(const FrameFlow&) = delete;
  FrameFlow& operator=(const FrameFlow&) = delete;

  // The calibration new frames take: the camera given, its radial distortion refined by
  // radial_calibration on keypoint-only maps (any thread).
  CameraModel Camera() const;
  // What the map tells marker location about the frame taken at `timestamp_s`.
  MapPrediction Prediction(double timestamp_s) const;
  // A frame whose markers were located (marker_fusion()): initialised, tracked or
  // relocalised, a keyframe decided, its pose recorded; `report` gets the outcome.
  void Process(Frame& frame, FrameReport& report);
  // Local mapping of a keyframe handed to MappingControl (mapping thread, or inline).
  LocalMappingResult MapKeyframe(KeyframeId keyframe);
  // Before the first frame: a saved map replaces the empty one.
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
  bool localize_only() const { return lifecycle_.localize_only(); }
  MarkerFusion& marker_fusion() { return marker_fusion_; }
  const MarkerFusion& marker_fusion() const { return marker_fusion_; }
  OnlineMarkerMapping& marker_mapping() { return marker_mapping_; }
  const OnlineMarkerMapping& marker_mapping() const { return marker_mapping_; }
  const WorldAnchoring& anchoring() const { return anchoring_; }
  const MapSession& map_session() const { return lifecycle_.session(); }

 private:
  // Tracking and keyframes (frame_flow.cc).
  void Initialize(Frame& frame, FrameReport& report);
  void FinishInitialization(const InitialMap& initial, Frame& frame, FrameReport& report);
  void Track(Frame& frame, FrameReport& report);
  void MaybeInsertKeyframe(Frame& frame, int num_inliers, FrameReport& report);
  // The map holds at most synchronous_young_map_keyframes keyframes.
  bool MapIsYoung() const {
    return static_cast<int>(map_->NumKeyframes()) <= options_.synchronous_young_map_keyframes;
  }
  // A frame's tracked pose against its reference keyframe, added to pose_history_.
  void RecordPose(const Frame& frame, KeyframeId reference);
  void CountStat(int FrameFlowStats::*counter, int amount = 1);

  // The current map's objects, lent to lifecycle_ and marker_world_, and its replacement
  // (frame_flow_maps.cc).
  MapLifecycleParts Parts();
  MarkerWorldParts MarkerParts();
  // A new mapper_ for map_: marker-keyframe guard and the BA's yield to a waiting keyframe.
  void MakeLocalMapper();
  void LocalizeInLoadedMap(Frame& frame, FrameReport& report);
  // A lost frame: the map is kept, or reset as lifecycle_ says.
  void HandleLostFrame(const Frame& frame, std::size_t frame_index);
  // Replaces the map by an empty one; the poses in the world stay, frozen.
  void ResetMap();

  // Radial calibration (frame_flow_calibration.cc). Tracking thread: a refined calibration
  // reaches the frame (undistorted again when extracted before it) and the kept matches.
  void FollowCalibration(Frame& frame);
  // Mapping thread, keypoint-only maps: radial_calibration_'s attempt when due.
  void CalibrateRadialDistortion();

  FrameFlowOptions options_;  // first: checked before anything is made from them
  CameraModel camera_;  // guarded by camera_mutex_: the mapping thread refines it
  mutable std::mutex camera_mutex_;
  CameraModel tracked_camera_;  // tracking thread: the calibration of the poses it recorded
  RadialCalibration radial_calibration_;
  MappingControl* mapping_;
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
  // Markers mapped in the world; only the mapping thread touches it while it runs and the map
  // is live.
  OnlineMarkerMapping marker_mapping_;
  // The current map's marker-world side: marker relocalisation and poses, world alignment.
  MarkerWorld marker_world_;
  // The maps one after the other: loaded, relocalised into, lost, closed, merged; the places.
  // Last: its places go before the map they index.
  MapLifecycle lifecycle_;
};

}  // namespace arucoslam
