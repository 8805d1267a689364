// FrameReport and FrameFlowStats: what the SLAM of one camera says about each frame it was
// given, and the counts it keeps over a run (part of the System's statistics).
#pragma once

#include <cstddef>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/slam/tracker.h"

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

// Counts of FrameFlow, written under the mutex it is given.
struct FrameFlowStats {
  int num_tracked = 0;           // frames with a pose
  // With a marker map, at Finish: frames without a pose in the trajectory that saw no marker
  // either (facing a plain wall between markers): where more markers, not better tracking,
  // would help.
  int num_unposed_without_markers = 0;
  int num_losses = 0;            // transitions tracking -> lost
  int num_initialization_attempts = 0;
  int num_initializations = 0;
  int num_keyframes_inserted = 0;
  int num_relocated_marker_poses = 0;  // marker poses located again in the final marker map
  int num_late_marker_poses = 0;       // frames without a pose located in it at the end
  int num_marker_only_poses = 0;  // frames whose pose came from markers alone
  int num_marker_relocalizations = 0;  // tracking restarted from a marker pose
  int num_map_relocalizations = 0;     // loaded map: restarted from a keyframe match
  int num_marker_initializations = 0;  // maps initialised from two marker locations
  int num_refined_frame_poses = 0;  // frames re-optimised against the final map at Finish
  int num_inconsistent_poses = 0;   // frames left out of Trajectory (pose_consistency)
  int num_radial_calibrations = 0;   // refinements of the radial distortion applied
  double radial_k1_correction = 0.0;  // their sum: what the calibration's k1 gained
};

// Adds `amount` to one of the counts under `mutex`: other threads read them.
inline void AddToStats(FrameFlowStats* stats, std::mutex* mutex, int FrameFlowStats::*counter,
                       int amount = 1) {
  std::lock_guard lock(*mutex);
  stats->*counter += amount;
}

}  // namespace arucoslam
