// VisitOptions for SystemOptions and the pipeline layer's options structs: each field once,
// with its comment (the protocol: util/options_visit.h). `arucoslam run --print-config` and
// `--config` write and read SystemOptions through these (io/config_file.h).
#pragma once

#include "arucoslam/pipeline/place_recognition.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/slam/options_visit.h"

namespace arucoslam {

template <class Visitor>
void VisitOptions(PlaceRecognitionOptions& o, Visitor& visit) {
  visit("loop_closing", o.loop_closing,
        "detect and close loops (run --no-loop-closing: false; relocalisation stays)");
  visit("database", o.database, "the keyframe database");
  visit("relocalizer", o.relocalizer, "relocalisation of lost tracking from the database");
  visit("detector", o.detector, "loop detection");
  visit("closer", o.closer, "loop correction");
  visit("global_bundle_adjustment", o.global_bundle_adjustment,
        "a global bundle adjustment after each closed loop");
  visit("global_ba", o.global_ba, "that global bundle adjustment");
  visit("loop_queue_capacity", o.loop_queue_capacity,
        "mapped keyframes waiting for the loop-closing thread");
  visit("max_marker_candidates", o.max_marker_candidates,
        "lost frame, no database pose: keyframes that saw its markers tried (0: off)");
}

// SystemOptions' fields in the order of system.h, where each is explained at length. Not
// here: the data `marker_map` (markers.json, run --markers), which also gives
// detector.dictionary, and `vocabulary` (run --vocabulary).
template <class Visitor>
void VisitOptions(SystemOptions& o, Visitor& visit) {
  visit("extractor", o.extractor, "ORB extraction");
  visit("initializer", o.initializer, "two-view map initialisation");
  visit("initial_map", o.initial_map, "refinement and test of the initial map");
  visit("tracker", o.tracker, "frame tracking");
  visit("keyframes", o.keyframes, "keyframe decision");
  visit("mapper", o.mapper, "local mapping");
  visit("blocking", o.blocking,
        "true: each frame tracked and mapped in turn on one thread, deterministic (run "
        "--blocking); false: local mapping on its own thread");
  visit("mapper_queue_capacity", o.mapper_queue_capacity,
        "keyframes waiting for the mapping thread");
  visit("yield_bundle_adjustment", o.yield_bundle_adjustment,
        "threaded: a local BA ends early once another keyframe waits");
  visit("synchronous_young_map_keyframes", o.synchronous_young_map_keyframes,
        "threaded: tracking waits for mapping while the map has at most this many keyframes");
  visit("live_source", o.live_source,
        "threaded, frames at a camera's pace (always for --device and --realtime): tracking never "
        "waits for the young map, which takes keyframes only from an idle mapper");
  visit("synchronous_until_aligned", o.synchronous_until_aligned,
        "threaded, marker map: ... and while the map is not aligned to the marker world");
  visit("max_initialization_gap_s", o.max_initialization_gap_s,
        "the initialisation reference is replaced after this long, seconds");
  visit("radial_calibration", o.radial_calibration,
        "the camera's radial distortion refined from the map");
  visit("map_session", o.map_session,
        "lost maps: reset, closed, merged into the next map, the gap bridged; the backfill");
  visit("detector", o.detector, "marker detection (with a marker map)");
  visit("marker_search", o.marker_search, "where each image's markers are searched");
  visit("marker_fusion", o.marker_fusion,
        "each frame's marker location and the verdict on keypoint poses against it");
  visit("relocate_marker_poses", o.relocate_marker_poses,
        "at the end, with mapped markers: frames located again in the final marker map");
  visit("world_anchoring", o.world_anchoring,
        "keyframes' marker locations: alignment of the map to the marker world, drift priors");
  visit("min_frames_between_anchor_keyframes", o.min_frames_between_anchor_keyframes,
        "before alignment a frame with a marker location becomes a keyframe after this many");
  visit("markers_in_local_ba", o.markers_in_local_ba,
        "aligned map: marker observations in local and global BA");
  visit("map_unknown_markers", o.map_unknown_markers, "aligned map: map markers it lacks");
  visit("whole_map_marker_adjustment", o.whole_map_marker_adjustment,
        "aligned map: one BA of the whole map with the markers when it closes and at Finish");
  visit("min_locating_marker_keyframes", o.min_locating_marker_keyframes,
        "mapped markers seen by this many keyframes locate frames (0: never)");
  visit("marker_mapping", o.marker_mapping, "mapping of markers absent from the marker map");
  visit("places", o.places, "place recognition: relocalisation and loops (with a vocabulary)");
  visit("min_marker_init_baseline_m", o.min_marker_init_baseline_m,
        "marker initialisation: two marker locations at least this far apart, metres");
  visit("min_marker_init_parallax_deg", o.min_marker_init_parallax_deg,
        "... and this median parallax of the triangulated points, degrees");
  visit("refine_frame_poses", o.refine_frame_poses,
        "at Finish every tracked frame is optimised again against the final map");
  visit("refine_min_inlier_fraction", o.refine_min_inlier_fraction,
        "its new pose is kept with at least this fraction of its matches still inliers");
  visit("drop_inconsistent_poses", o.drop_inconsistent_poses,
        "frames far off the path between their keyframes are left out of the trajectory");
  visit("pose_consistency", o.pose_consistency, "that test");
}

}  // namespace arucoslam
