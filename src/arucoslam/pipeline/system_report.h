// FrameReport and SystemStats: what System says about each frame it was given, and its
// counts and timings over a run (`arucoslam run` writes them to stats.json).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/markers/detector.h"
#include "arucoslam/pipeline/place_recognition.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/tracker.h"
#include "arucoslam/slam/world_anchoring.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {

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
  int num_radial_calibrations = 0;   // refinements of the radial distortion applied
  double radial_k1_correction = 0.0;  // their sum: what the calibration's k1 gained
  int num_inconsistent_poses = 0;   // frames left out of Trajectory (pose_consistency)
};

}  // namespace arucoslam
