// TrackedPose: one frame's pose as PoseHistory keeps it, held relative to its reference
// keyframe so that it follows the keyframe when the map is corrected.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <vector>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/map/ids.h"
#include "arucoslam/optim/marker_pose_optimizer.h"

namespace arucoslam {

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
  // What tracking matched in the frame (refine_frame_poses; emptied after the refinement).
  std::vector<FrameMatch> matches;
  std::vector<MarkerPoseObservation> markers;  // known markers only
  // The frame's marker location while its map is not in the world: its pose if the map
  // never gets there.
  std::optional<Rigid3> marker_cam_from_world;
  // The markers a frame posed by markers saw (PoseHistory::RelocateInMarkerMap).
  std::vector<MarkerObservation> seen_markers;
};

struct UnposedMarkerFrame {  // a frame that saw markers but got no pose
  double timestamp_s = 0.0;
  std::vector<MarkerObservation> markers;
};

}  // namespace arucoslam
