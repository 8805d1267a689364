// LoadedMapRelocalizer: a frame's pose in a map loaded from a file, without a place database:
// brute-force matching against a few of its keyframes per frame (round robin over the map),
// a pose-only optimisation from the best one, then tracking from that pose.
#pragma once

#include <cstddef>
#include <optional>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/map/map.h"
#include "arucoslam/slam/tracker.h"

namespace arucoslam {

class LoadedMapRelocalizer {
 public:
  // Matching, pose optimisation and inlier minimum as the tracker's (reference_search, pose,
  // min_pose_inliers).
  explicit LoadedMapRelocalizer(const TrackerOptions& tracking);

  // The pose of `frame` from this frame's share of the keyframes of `map`: the keyframe with
  // the most descriptor matches to map points, the frame's pose optimised from that
  // keyframe's. None when too few of those matches stay inliers.
  std::optional<Rigid3> SeedPose(const Map& map, const Frame& frame);
  // SeedPose refined by `tracker` against the local map (tracking resumes there): the
  // tracker's number of inliers, or none. `frame_index` is for the log.
  std::optional<int> Relocalize(const Map& map, Tracker& tracker, Frame& frame,
                                std::size_t frame_index);

 private:
  TrackerOptions tracking_;
  std::size_t next_keyframe_ = 0;  // round-robin position among the map's keyframes
};

}  // namespace arucoslam
