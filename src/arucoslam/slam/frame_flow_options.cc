#include "arucoslam/slam/frame_flow_options.h"

#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool FrameFlowOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Nested("tracker", tracker);
  check.Nested("keyframes", keyframes);
  check.Nested("mapper", mapper);
  check.Nested("map_session", map_session);
  check.Nested("radial_calibration", radial_calibration);
  check.Nested("pose_consistency", pose_consistency);
  check.AtLeast("synchronous_young_map_keyframes", synchronous_young_map_keyframes, 0);
  check.Nested("marker_fusion", marker_fusion);
  check.Nested("world_anchoring", world_anchoring);
  check.AtLeast("min_frames_between_anchor_keyframes", min_frames_between_anchor_keyframes, 0);
  check.Nested("marker_mapping", marker_mapping);
  check.InRange("refine_min_inlier_fraction", refine_min_inlier_fraction, 0.0, 1.0,
                Interval::kOpenClosed);
  check.Nested("initialization", initialization);
  return check.ok();
}

}  // namespace arucoslam
