// FrameFlowOptions: the settings of the synchronous SLAM of one camera (FrameFlow), one nested
// options struct per component it drives.
#pragma once

#include <optional>
#include <string>

#include "arucoslam/geometry/pose_consistency.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/slam/keyframe_policy.h"
#include "arucoslam/slam/local_mapper.h"
#include "arucoslam/slam/map_initializer.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/online_marker_mapping.h"
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
  std::optional<MarkerMap> marker_map;          // the known markers; none: keypoints only
  MarkerFusionOptions marker_fusion;
  WorldAnchoringOptions world_anchoring;
  OnlineMarkerMappingOptions marker_mapping;
  // Frames tracked between two keyframes kept for their marker location before the alignment.
  int min_frames_between_anchor_keyframes = 1;
  // Threaded mapping: a keyframe is mapped before the next frame while the map has at most
  // this many keyframes, and (synchronous_until_aligned) until it is in the marker world.
  int synchronous_young_map_keyframes = 20;
  // Frames come at a camera's pace and are dropped while tracking waits: tracking never waits
  // for the young map's keyframes; while the map has at most synchronous_young_map_keyframes,
  // a keyframe goes in only when the mapper is idle instead, so each is mapped before the next.
  bool live_source = false;
  bool synchronous_until_aligned = false;
  bool inline_mapping = true;           // keyframes are mapped between frames (blocking mode)
  bool yield_bundle_adjustment = true;  // threaded: a local BA yields to a waiting keyframe
  bool relocate_marker_poses = true;    // at Finish, marker poses located in the final markers
  bool refine_frame_poses = true;       // at Finish, frame poses against the final map
  double refine_min_inlier_fraction = 0.5;
  bool drop_inconsistent_poses = true;  // Trajectory leaves out poses off their keyframes
  PoseConsistencyOptions pose_consistency;

  // The first bad field named in *why ("tracker.min_pose_inliers must be ...").
  bool Check(std::string* why = nullptr) const;
};

}  // namespace arucoslam
