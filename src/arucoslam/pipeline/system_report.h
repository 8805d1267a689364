// SystemStats: the counts and timings of a System over a run (`arucoslam run` writes them to
// stats.json); FrameReport, what it says about each frame, is in slam/frame_report.h.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/pipeline/place_recognition.h"
#include "arucoslam/slam/frame_report.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/tracker.h"
#include "arucoslam/slam/world_anchoring.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {

// FrameFlowStats: the counts the SLAM flow keeps.
struct SystemStats : FrameFlowStats {
  TimingStats extraction_ms;     // per frame
  TimingStats tracking_ms;       // per frame: initialisation or tracking + keyframe decision
                                 // (no extraction, no local mapping)
  TimingStats frame_ms;          // per frame, everything on the tracking thread
  TimingStats local_mapping_ms;  // per keyframe
  // Its steps, per keyframe: new points, duplicate fusion, local BA (with building the
  // problem and writing it back), point and keyframe culling.
  TimingStats triangulation_ms;
  TimingStats fusion_ms;
  TimingStats local_bundle_adjustment_ms;
  TimingStats culling_ms;
  int num_frames = 0;
  int num_lost = 0;              // frames in state lost
  TimingStats marker_ms;          // per frame with a marker map: detection and location
  // Per frame with a marker map: what the frame waits for markers (detection runs during
  // extraction; the time from extraction's end until detections are ready) plus location.
  TimingStats marker_wait_ms;
  int num_full_marker_scans = 0;  // frames whose markers were searched in the whole image
  MarkerFusionStats marker_fusion;     // marker locations and verdicts on keypoint poses
  WorldAnchoringStats world_anchoring;  // alignments to the marker world, drift corrections
  PlaceRecognitionStats places;        // relocalisation and loops (with a vocabulary)
  MapSessionStats map_session;         // resets, closed maps, merges and bridged gaps
  int num_whole_map_marker_adjustments = 0;  // bundle adjustments of a whole map with markers
  int num_yielded_bundle_adjustments = 0;  // local BAs ended early for a waiting keyframe
};

}  // namespace arucoslam
