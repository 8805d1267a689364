// Output check of tracked poses against the keyframes around them in time: a frame whose
// position lies far from the path between its two neighbouring keyframes is left out.
#pragma once

#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct StampedPose {
  double timestamp_s = 0.0;
  Rigid3 world_from_cam;
};

// A frame tracked with few inliers (a plain wall, a young map) can sit far off the
// keyframes it was tracked between while those keyframes, optimised with many views, are
// right; such frames can alternate from one frame to the next between two places. Between
// two keyframes at most max_keyframe_gap_s apart in time, a camera cannot stray from the
// straight line joining them by more than their distance apart (it moves smoothly); a frame
// farther than that and than max_offset_m from the point of the line at its time is dropped.
struct PoseConsistencyOptions {
  double max_offset_m = 0.25;
  double max_keyframe_gap_s = 1.0;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Above("max_offset_m", max_offset_m, 0.0);
    check.Above("max_keyframe_gap_s", max_keyframe_gap_s, 0.0);
    return check.ok();
  }
};

// The frames (in time order) that agree with `keyframes` (any order, same world frame).
// Frames before the first keyframe, after the last one, or between keyframes farther apart
// in time than max_keyframe_gap_s are kept unchecked. `num_dropped` (optional) counts the rest.
std::vector<StampedPose> DropPosesOffTheirKeyframes(const std::vector<StampedPose>& frames,
                                                    std::vector<StampedPose> keyframes,
                                                    const PoseConsistencyOptions& options,
                                                    int* num_dropped = nullptr);

}  // namespace arucoslam
