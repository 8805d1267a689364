// OnlineMarkerMapping: the markers a run maps in the marker world, from the keyframes of a map
// aligned to it or, before that, from frames posed by markers; publishes those that locate frames.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "arucoslam/map/frame.h"
#include "arucoslam/map/map.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/optim/essential_graph.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/marker_mapper.h"
#include "arucoslam/slam/world_anchoring.h"

namespace arucoslam {

struct OnlineMarkerMappingOptions {
  // The mapper of markers absent from the known map (its map_unknown is and-ed with
  // map_unknown_markers).
  MarkerMapperOptions mapper;
  // Map markers the known map lacks (default true).
  bool map_unknown_markers = true;
  // Once the map is aligned, its marker landmarks join local and loop bundle adjustment
  // (default true).
  bool markers_in_local_ba = true;
  // An aligned map gets one bundle adjustment of all its keyframes and points with every
  // marker view when it is closed and at the end of the run (default true); false: at the end
  // only the mapped markers are refined.
  bool whole_map_adjustment = true;
  // Mapped markers seen by at least this many keyframes locate frames like known ones
  // (default 3; 0: never).
  int min_locating_keyframes = 3;

  bool Check(std::string* why = nullptr) const;
};

struct OnlineMarkerMappingStats {
  int num_whole_map_adjustments = 0;  // successful adjustments of a whole map with markers
};

// One run's marker mapping. Until the map is aligned the tracking thread feeds marker views;
// from Start to CloseMap only the mapping thread feeds it (Start and CloseMap run while the
// mapping thread is stopped). LocatingMarkers may be read from any thread.
class OnlineMarkerMapping {
 public:
  // `known`: the marker map of the run (none: every call does nothing).
  OnlineMarkerMapping(std::optional<MarkerMap> known, const OnlineMarkerMappingOptions& options);

  const OnlineMarkerMappingOptions& options() const { return options_; }
  // The current map is aligned and feeds the mapper (Start until CloseMap).
  bool live() const { return live_; }
  // A mapper exists: markers were known or seen in the world.
  bool has_mapper() const { return mapper_ != nullptr; }
  OnlineMarkerMappingStats stats() const { return stats_; }

  // With an empty known map: the largest marker of the first frame with detections becomes the
  // world origin (MarkerMapper::AdoptWorldOrigin). Not once live.
  void AdoptWorldOrigin(const std::vector<MarkerDetection>& detections, const CameraModel& camera);
  // A frame posed by markers alone (`fix`) while no map is live: maps unknown markers as a
  // marker view; the mapped markers are refined as the views grow by a fifth.
  void AddMarkerView(const Frame& frame, const std::optional<MarkerFix>& fix);

  // The current map was aligned to the world: it feeds the mapper from now on. False without a
  // known map.
  bool Start();
  // The marker landmarks local and loop bundle adjustment estimate with the keyframes (null:
  // not live, or markers_in_local_ba off).
  MarkerLandmarks* landmarks_for_bundle_adjustment();
  // The marker landmarks that move with the map on a re-alignment (null: not live).
  MarkerLandmarks* live_landmarks();
  // The keyframes of `map` not fed yet (those mapped before the alignment).
  std::vector<KeyframeId> UnfedKeyframes(const Map& map) const;
  // Mapping thread: the markers `keyframe` saw, at its pose in `map`.
  void AddKeyframe(const Map& map, KeyframeId keyframe);
  // The live map was moved by `new_from_old` (a re-alignment): the recorded keyframe poses
  // follow, but those of `stay`.
  void ApplySimilarity(const Sim3& new_from_old, const std::set<KeyframeId>* stay);
  // The map is being replaced: its keyframes are retired at their world poses. Returns the
  // closed map's generation (-1: no mapper).
  int CloseMap();
  // The closed map of `generation` was merged under `new_ids`: its records are live again.
  // Returns how many.
  int ReviveClosedMap(int generation, const std::map<KeyframeId, KeyframeId>& new_ids);
  // Camera-centre priors of whole-map adjustments (the bridge over a tracking gap).
  void SetPositionPriors(const std::vector<KeyframePosePrior>& priors);

  // Mapping thread: the drift correction `anchoring` asks for at `keyframe` (none: not live).
  std::optional<DriftCorrectionDecision> DecideDriftCorrection(const Map& map,
                                                               const WorldAnchoring& anchoring,
                                                               KeyframeId keyframe) const;
  // Carries `decision` out: a pose graph (`graph`) of `map` with its marker priors.
  EssentialGraphResult CorrectDrift(Map* map, KeyframeId keyframe,
                                    const DriftCorrectionDecision& decision,
                                    const EssentialGraphOptions& graph) const;

  // Whether AdjustWholeMap applies (live, whole_map_adjustment).
  bool AdjustsWholeMap() const;
  // Bundle adjustment of the whole live map with every marker view (`when` for the log); the
  // caller keeps other writers of the landmarks away. True on success.
  bool AdjustWholeMap(Map* map, const char* when);
  // End of the run without a whole-map adjustment: the mapped markers alone are refined.
  void RefineMappedMarkers(const Map& map);

  // Known and mapped markers that locate frames: the known map until a mapped marker locates
  // (null without a known map).
  std::shared_ptr<const MarkerMap> LocatingMarkers() const;
  // The known markers as given and the mapped ones (fixed: false); empty without a known map.
  MarkerMap ToMarkerMap() const;

 private:
  MarkerMapper& EnsureMapper();
  void PublishLocatingMarkers();

  std::optional<MarkerMap> known_;
  OnlineMarkerMappingOptions options_;
  std::unique_ptr<MarkerMapper> mapper_;
  bool live_ = false;
  int marker_views_refined_ = 0;  // marker views at the last refinement (AddMarkerView)
  OnlineMarkerMappingStats stats_;
  mutable std::mutex locating_mutex_;
  std::shared_ptr<const MarkerMap> locating_markers_;
};

}  // namespace arucoslam
