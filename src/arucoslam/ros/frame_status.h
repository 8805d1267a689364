// FrameStatus: what the node reports about each frame it processed (status topic). Free of
// ROS and C++20 types so that both the SLAM side and the message side include it.
#pragma once

#include <cstddef>
#include <string>

namespace arucoslam {

struct FrameStatus {
  std::string state;           // "not initialised", "tracking", "lost", "waiting for camera"
  bool has_pose = false;       // a pose was published for the frame
  bool relocalised = false;    // tracking came back on this frame after a loss
  bool world_aligned = false;  // poses are in the marker world frame (metric)
  bool marker_pose = false;    // the pose comes from the markers alone
  int num_markers = 0;         // known markers detected in the image
  std::size_t num_keyframes = 0;
  std::size_t num_map_points = 0;
};

}  // namespace arucoslam
