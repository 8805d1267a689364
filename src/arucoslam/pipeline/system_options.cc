#include "arucoslam/pipeline/system_options.h"

#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool SystemOptions::Check(std::string* why) const {
  OptionCheck check(why);
  // What only the System has, and what the flow's options hold under other names.
  check.Nested("extractor", extractor);
  check.Nested("initializer", initializer);
  check.Nested("initial_map", initial_map);
  check.AtLeast("mapper_queue_capacity", mapper_queue_capacity, 1);
  check.Above("max_initialization_gap_s", max_initialization_gap_s, 0.0);
  check.Nested("detector", detector);
  check.Nested("places", places);
  check.Nested("marker_mapping", marker_mapping);
  check.AtLeast("min_locating_marker_keyframes", min_locating_marker_keyframes, 0);
  check.Above("min_marker_init_baseline_m", min_marker_init_baseline_m, 0.0);
  check.AtLeast("min_marker_init_parallax_deg", min_marker_init_parallax_deg, 0.0);
  check.Nested("marker_search", marker_search);
  // The rest, named alike in the flow's options.
  check.Unprefixed(FlowOptions());
  return check.ok();
}

FrameFlowOptions SystemOptions::FlowOptions() const {
  FrameFlowOptions flow;
  flow.initialization.two_view = initializer;
  flow.initialization.initial_map = initial_map;
  flow.initialization.max_reference_gap_s = max_initialization_gap_s;
  flow.initialization.markers.min_baseline_m = min_marker_init_baseline_m;
  flow.initialization.markers.min_parallax_deg = min_marker_init_parallax_deg;
  flow.initialization.markers.alignment = world_anchoring.alignment;
  flow.tracker = tracker;
  flow.keyframes = keyframes;
  flow.mapper = mapper;
  flow.map_session = map_session;
  flow.radial_calibration = radial_calibration;
  flow.marker_map = marker_map;
  flow.marker_fusion = marker_fusion;
  flow.world_anchoring = world_anchoring;
  flow.marker_mapping.mapper = marker_mapping;
  flow.marker_mapping.map_unknown_markers = map_unknown_markers;
  flow.marker_mapping.markers_in_local_ba = markers_in_local_ba;
  flow.marker_mapping.whole_map_adjustment = whole_map_marker_adjustment;
  flow.marker_mapping.min_locating_keyframes = min_locating_marker_keyframes;
  flow.min_frames_between_anchor_keyframes = min_frames_between_anchor_keyframes;
  flow.synchronous_young_map_keyframes = synchronous_young_map_keyframes;
  flow.live_source = live_source;
  flow.synchronous_until_aligned = synchronous_until_aligned;
  flow.inline_mapping = blocking;
  flow.yield_bundle_adjustment = yield_bundle_adjustment;
  flow.relocate_marker_poses = relocate_marker_poses;
  flow.refine_frame_poses = refine_frame_poses;
  flow.refine_min_inlier_fraction = refine_min_inlier_fraction;
  flow.drop_inconsistent_poses = drop_inconsistent_poses;
  flow.pose_consistency = pose_consistency;
  return flow;
}

}  // namespace arucoslam
