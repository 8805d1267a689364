#include "arucoslam/pipeline/system_options.h"

#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool SystemOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Nested("extractor", extractor);
  check.Nested("initializer", initializer);
  check.Nested("initial_map", initial_map);
  check.Nested("tracker", tracker);
  check.Nested("keyframes", keyframes);
  check.Nested("mapper", mapper);
  check.AtLeast("mapper_queue_capacity", mapper_queue_capacity, 1);
  check.Above("max_initialization_gap_s", max_initialization_gap_s, 0.0);
  check.Nested("map_session", map_session);
  check.Nested("radial_calibration", radial_calibration);
  check.Nested("pose_consistency", pose_consistency);
  check.AtLeast("synchronous_young_map_keyframes", synchronous_young_map_keyframes, 0);
  check.Nested("detector", detector);
  check.Nested("marker_fusion", marker_fusion);
  check.Nested("world_anchoring", world_anchoring);
  check.Nested("places", places);
  check.AtLeast("min_frames_between_anchor_keyframes", min_frames_between_anchor_keyframes, 0);
  check.Nested("marker_mapping", marker_mapping);
  check.Above("min_marker_init_baseline_m", min_marker_init_baseline_m, 0.0);
  check.AtLeast("min_marker_init_parallax_deg", min_marker_init_parallax_deg, 0.0);
  check.Nested("marker_search", marker_search);
  check.InRange("refine_min_inlier_fraction", refine_min_inlier_fraction, 0.0, 1.0,
                Interval::kOpenClosed);
  return check.ok();
}

}  // namespace arucoslam
