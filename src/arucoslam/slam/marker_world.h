// MarkerWorld: the marker-world side of FrameFlow's current map: tracking restarted from a
// marker pose, marker-only poses, the Sim(3) alignment of the keypoint map to the world (the
// online marker mapping wired on each), and the drift correction from mapped markers.
#pragma once

#include <mutex>

#include "arucoslam/map/map.h"
#include "arucoslam/optim/essential_graph.h"
#include "arucoslam/slam/frame_flow_options.h"
#include "arucoslam/slam/frame_report.h"
#include "arucoslam/slam/local_mapper.h"
#include "arucoslam/slam/map_lifecycle.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/online_marker_mapping.h"
#include "arucoslam/slam/place_index.h"
#include "arucoslam/slam/pose_history.h"
#include "arucoslam/slam/tracker.h"
#include "arucoslam/slam/world_anchoring.h"

namespace arucoslam {

// The objects of the current map that the marker world works on, owned by its caller. Taken
// anew for each call: a reset replaces the map, its tracker and its mapper.
struct MarkerWorldParts {
  Map& map;
  Tracker& tracker;
  LocalMapper& mapper;
  PoseHistory& pose_history;
  WorldAnchoring& anchoring;
  MarkerFusion& marker_fusion;
  OnlineMarkerMapping& marker_mapping;
  MapLifecycle& lifecycle;
  MappingControl& mapping;

  MapLifecycleParts ForLifecycle() const {
    return {map, tracker, pose_history, anchoring, marker_fusion, marker_mapping};
  }
};

// Decides nothing itself (WorldAnchoring, MarkerFusion and OnlineMarkerMapping do): carries
// their decisions out on the map, the tracker, the poses and the places. Tracking thread but
// for CorrectDrift (mapping thread).
class MarkerWorld {
 public:
  // Counts go to `stats` under `stats_mutex`.
  MarkerWorld(const FrameFlowOptions& options, FrameFlowStats* stats, std::mutex* stats_mutex);

  // A frame not tracked, in a world-aligned map with a marker location: tracked again from
  // the marker pose. True: tracked, `report` says so.
  bool Relocalize(const MarkerWorldParts& parts, Frame& frame, FrameReport& report);
  // Aligns the map to the world when the anchoring decides so; `frame` (the current one, its
  // pose in the map) is carried along, and a closed map waiting for the world is merged.
  void MaybeAlign(const MarkerWorldParts& parts, Frame& frame);
  // The frame's pose from its marker location alone, recorded and reported.
  void RecordMarkerPose(const MarkerWorldParts& parts, const Frame& frame, FrameReport& report);
  // Mapping thread, after the keyframe's markers were mapped: the pose-graph correction when
  // they contradict its pose; `places` (null: none) learn of the move.
  void CorrectDrift(Map& map, KeyframeId keyframe, WorldAnchoring& anchoring,
                    OnlineMarkerMapping& marker_mapping, PlaceIndex* places);

 private:
  // The marker mapping wired to the map, the local mapper and the places on each alignment.
  void StartMarkerMapping(const MarkerWorldParts& parts);

  EssentialGraphOptions correction_graph_;
  bool priors_in_loops_;
  FrameFlowStats* stats_;
  std::mutex* stats_mutex_;
};

}  // namespace arucoslam
