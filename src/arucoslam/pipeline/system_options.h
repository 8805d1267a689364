// SystemOptions: every setting of the SLAM pipeline, one nested options struct per component;
// `arucoslam run --print-config` writes them and `--config` reads them (options_visit.h).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "arucoslam/feature/orb_extractor.h"
#include "arucoslam/geometry/pose_consistency.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/detector_regions.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/pipeline/place_recognition.h"
#include "arucoslam/slam/frame_flow.h"
#include "arucoslam/slam/initializer.h"
#include "arucoslam/slam/keyframe_policy.h"
#include "arucoslam/slam/local_mapper.h"
#include "arucoslam/slam/map_initialization.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/radial_calibration.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/marker_mapper.h"
#include "arucoslam/slam/tracker.h"
#include "arucoslam/slam/world_anchoring.h"

namespace arucoslam {

struct SystemOptions {
  // The extractor's defaults, but 5 grey levels for the FAST threshold of low-contrast cells
  // (the extractor's own default is 7): keypoints stay on the faint marks of plain walls.
  OrbExtractorOptions extractor = [] {
    OrbExtractorOptions options;
    options.min_fast_threshold = 5;
    return options;
  }();
  InitializerOptions initializer;
  InitialMapOptions initial_map;
  TrackerOptions tracker;
  KeyframePolicyOptions keyframes;
  LocalMapperOptions mapper;
  // true: each frame is tracked and its keyframe mapped in the caller's thread before
  // ProcessImage returns (deterministic). false: local mapping runs on its own thread.
  bool blocking = true;
  int mapper_queue_capacity = 3;  // keyframes waiting for the mapping thread
  // Threaded mode: a local BA ends after its current iteration (at least the mapper's
  // min_iterations_before_stop) once another keyframe waits in the queue, so a new view gets
  // its points mapped without waiting for the BAs of the keyframes before it (ORB-SLAM's
  // abort). Blocking mode: no keyframe waits.
  bool yield_bundle_adjustment = true;
  // Threaded mode: while the map holds at most this many keyframes, tracking waits until
  // each new keyframe is mapped before it takes the next frame, as in blocking mode: a young
  // map tracked ahead of its local BA drifts in scale. 0: tracking never waits. A live
  // source never waits (live_source).
  int synchronous_young_map_keyframes = 20;
  // Threaded mode, frames at a camera's pace (`run` sets it for a live camera and for
  // --realtime): tracking never waits for the young map, whose frames the camera would drop;
  // while it holds at most synchronous_young_map_keyframes keyframes, a keyframe goes in only
  // when the mapper is idle instead, so that each is still mapped before the next.
  bool live_source = false;
  // With a marker map: tracking also waits for every keyframe of a map not yet aligned to the
  // marker world. Off by default: a live camera would lose the frames of every such wait.
  bool synchronous_until_aligned = false;
  // The initialisation reference frame is replaced when the current frame is more than this
  // many seconds later (a reference is also replaced when too few matches are left). Long
  // enough for a vehicle that starts from rest to build up parallax.
  double max_initialization_gap_s = 3.0;
  // What becomes of a map that lost tracking (reset, closed, merged into the next one, the
  // gap bridged) and how many frames a new map's backfill tracks (slam/map_session.h).
  MapSessionOptions map_session;
  // The camera's radial distortion refined from the map, keypoint-only runs
  // (slam/radial_calibration.h).
  RadialCalibrationOptions radial_calibration;

  // Known markers (markers.json). When set, markers are detected in every image and located
  // (LocateCamera): frames without a keypoint pose get the marker pose, the keypoint map is
  // aligned to the world (Sim3, metric scale), tracking restarts from marker poses, and
  // aligned frames are optimised with the markers' corners. Unset: keypoints only.
  std::optional<MarkerMap> marker_map;
  // The detector's defaults, but without the edge refit of 20-60 px markers' corners
  // (DetectorOptions::edge_refinement): its corners are the more accurate ones, yet the SLAM
  // with them was worse on most simulated routes (BENCHMARKS.md, "Marker corners refitted
  // from their edges").
  DetectorOptions detector = [] {
    DetectorOptions options;
    options.edge_refinement = false;
    return options;
  }();
  // Where each image's markers are searched: the whole image every full_scan_interval
  // frames and whenever the previous frame has no pose in the marker world, else around the
  // known (and mapped) markers projected with that pose and the previous frame's detections
  // (MarkerDetector::DetectInRegions, about 10x cheaper). Markers missing from marker_map
  // are found at the whole-image searches, then followed. full_scan_interval 1: always the
  // whole image.
  MarkerSearchOptions marker_search;
  // Each frame's marker location, its ambiguity, and the verdict on keypoint poses that
  // contradict it (a look-alike place).
  MarkerFusionOptions marker_fusion;
  // At Finish, when markers were mapped: frames posed by markers are located again in the
  // final marker map, and frames that saw markers but got no pose are located in it.
  bool relocate_marker_poses = true;
  // The keyframes' marker locations: when the map is aligned (and realigned) to the marker
  // world, and when they correct its drift.
  WorldAnchoringOptions world_anchoring;
  // Until the first alignment, a frame with a usable marker location becomes a keyframe when
  // at least this many frames passed since the last keyframe.
  int min_frames_between_anchor_keyframes = 1;
  // Once the map is world-aligned, keyframes' marker observations join local BA and the
  // global BA after a loop (known markers fixed) and markers the map lacks are mapped
  // (slam/online_marker_mapping.h).
  bool markers_in_local_ba = true;
  bool map_unknown_markers = true;
  // A world-aligned map gets one bundle adjustment of all its keyframes and points with every
  // marker-corner observation (known markers fixed, mapped ones estimated, views of culled
  // keyframes kept) when it is closed after a loss and at Finish (corner weights:
  // MarkerMapperOptions). false: at Finish only the mapped markers are refined.
  bool whole_map_marker_adjustment = true;
  // Mapped markers seen by at least this many keyframes locate frames like known ones
  // (marker poses and relocalisation where the known map has no marker). 0: never.
  int min_locating_marker_keyframes = 3;
  MarkerMapperOptions marker_mapping;

  // Bag-of-words vocabulary. When set, keyframes enter a place database: lost tracking is
  // relocalised from it and, with places.loop_closing, loops are closed. Null: neither.
  std::shared_ptr<const Vocabulary> vocabulary;
  PlaceRecognitionOptions places;
  // Marker initialisation: when the initialisation reference and the current frame both
  // have a usable marker location with centres at least this far apart (metres), the
  // matches are triangulated with the markers' relative pose and the map starts in the world.
  double min_marker_init_baseline_m = 0.5;
  // ... and at least this median parallax of the triangulated points (degrees).
  double min_marker_init_parallax_deg = 1.0;
  // At Finish, after the last map adjustments, every frame tracked in the map is optimised
  // again (motion only) against the final positions of the map points it matched when it
  // was tracked, plus the known markers it saw, starting from its pose relative to its
  // reference keyframe: that offset was fixed before the map's later corrections. The new
  // pose is kept when at least refine_min_inlier_fraction of those matches (and at least the
  // tracker's min_pose_inliers) are still in the map and stay inliers.
  // Keeps each tracked frame's matches until Finish. false: frames keep their keyframe
  // offsets.
  bool refine_frame_poses = true;
  double refine_min_inlier_fraction = 0.5;
  // Trajectory leaves out the frames that lie far off the path between the keyframes around
  // them in time (pose_consistency.h). false: every tracked pose is output.
  bool drop_inconsistent_poses = true;
  PoseConsistencyOptions pose_consistency;

  bool Check(std::string* why = nullptr) const;
  // The options of the SLAM flow these make.
  FrameFlowOptions FlowOptions() const;
};

}  // namespace arucoslam
