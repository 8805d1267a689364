// MapLifecycle: the maps of a FrameFlow run one after the other: a saved map started from and
// relocalised into, the place database's relocalisation and loop corrections followed, a lost
// map reset, closed and merged into the next one, the gap bridged and a new map backfilled.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "arucoslam/geometry/pose_consistency.h"
#include "arucoslam/map/map.h"
#include "arucoslam/slam/frame_flow_options.h"
#include "arucoslam/slam/frame_report.h"
#include "arucoslam/slam/loaded_map_relocalizer.h"
#include "arucoslam/slam/map_initializer.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/online_marker_mapping.h"
#include "arucoslam/slam/place_index.h"
#include "arucoslam/slam/pose_history.h"
#include "arucoslam/slam/tracker.h"
#include "arucoslam/slam/world_anchoring.h"

namespace arucoslam {

// A new PlaceIndex for a map; null without a vocabulary.
using PlaceIndexFactory = std::function<std::unique_ptr<PlaceIndex>(Map& map)>;

// The objects of the current map that the lifecycle works on, owned by its caller. Taken
// anew for each call: a reset replaces the map and its tracker.
struct MapLifecycleParts {
  Map& map;
  Tracker& tracker;
  PoseHistory& pose_history;
  WorldAnchoring& anchoring;
  MarkerFusion& marker_fusion;
  OnlineMarkerMapping& marker_mapping;
};

// Owns the map session (lost maps, closed maps, the bridge, the backfill), the place database
// of the current map and the relocalisation into a loaded map; tracking thread only, but for
// places() and the map-move lock the mapping thread also takes.
class MapLifecycle {
 public:
  // Counts go to `stats` under `stats_mutex`.
  MapLifecycle(const FrameFlowOptions& options, PlaceIndexFactory make_places,
               FrameFlowStats* stats, std::mutex* stats_mutex);
  ~MapLifecycle();
  MapLifecycle(const MapLifecycle&) = delete;
  MapLifecycle& operator=(const MapLifecycle&) = delete;

  // The current map's place database; null without a vocabulary.
  PlaceIndex* places() const { return places_.get(); }
  MapSession& session() { return session_; }
  const MapSession& session() const { return session_; }
  bool map_loaded() const { return map_loaded_; }
  bool localize_only() const { return localize_only_; }

  // A new place database for `parts.map` (the first map, and each after a reset).
  void MakePlaces(const MapLifecycleParts& parts);
  // Before the first frame: a saved map replaces the empty one.
  void StartFromMap(const MapLifecycleParts& parts, MapData map, bool world_aligned,
                    bool localize_only);

  // Relocalisation of a frame not tracked: from the place database (the pose refined against
  // the local map, and confirmed by the frame's markers in a world-aligned map), or by
  // matching the keyframes of a loaded map without places. True: tracked again, `report` says so.
  bool RelocalizeWithPlaces(const MapLifecycleParts& parts, Frame& frame, FrameReport& report);
  bool RelocalizeInLoadedMap(const MapLifecycleParts& parts, Frame& frame, FrameReport& report);

  // A new map's first two keyframes: the kept frames backfilled from `second` back in time,
  // the keyframes given to the places, the bridge prior noted.
  void MapInitialized(const MapLifecycleParts& parts, const InitialMap& initial,
                      const Frame& second);
  // After a loop correction or a drift correction: the tracker's last pose follows its
  // reference keyframe into the corrected map; poses of culled keyframes are re-anchored first.
  void FollowMapCorrections(const MapLifecycleParts& parts);
  // The map was moved as a whole: the keyframe poses the re-anchoring compares against.
  void RefreshKeyframePoseCache(const MapLifecycleParts& parts);
  // Held while the map is moved from outside (world alignment); empty without places.
  std::unique_lock<std::mutex> LockPlacesForMapMove();
  // Bundle adjustment of the whole world-aligned map with every marker view (`when` is for
  // the log); mapping must be stopped and the places' edit lock free.
  void AdjustWholeMapWithMarkers(Map& map, OnlineMarkerMapping& marker_mapping, const char* when);

  // A lost frame: true when the map must be reset now (the session's decision).
  bool OnLostFrame(const MapLifecycleParts& parts, const Frame& frame, std::size_t frame_index);
  // The reset, before the caller replaces the map: what must outlive it is kept, the poses
  // in the world frozen, the places dropped. True when the map is kept whole for a merge.
  bool CloseMap(const MapLifecycleParts& parts);
  // The reset, once the caller replaced the map by an empty one (`parts`).
  void StartNewMap(const MapLifecycleParts& parts, bool kept_for_merge);
  // Once the current map is in the world: the closed map joins it, with its frozen poses,
  // marker views, marker priors and place entries, and the new map is corrected across the
  // tracking gap. True when it merged.
  bool MergeClosedMap(const MapLifecycleParts& parts);

  // The keyframe poses and map points of the closed maps and, when in the world frame (or
  // without markers), of `map`; keyframes in time order.
  std::vector<StampedPose> KeyframePoses(const Map& map, bool world_aligned) const;
  std::vector<Eigen::Vector3d> MapPoints(const Map& map, bool world_aligned) const;

 private:
  void CorrectAcrossBridge(const MapLifecycleParts& parts);
  // The session's held bridge priors to the marker mapper and the places.
  void HandOutBridgePriors(OnlineMarkerMapping& marker_mapping);
  void BackfillInitialization(const MapLifecycleParts& parts, const Frame& second,
                              KeyframeId first_id, KeyframeId second_id);

  TrackerOptions tracker_options_;
  EssentialGraphOptions correction_graph_;
  PoseConsistencyOptions pose_consistency_;
  bool marker_world_;  // a marker map is given
  PlaceIndexFactory make_places_;
  FrameFlowStats* stats_;
  std::mutex* stats_mutex_;

  MapSession session_;
  bool map_loaded_ = false;  // started from a saved map (StartFromMap)
  bool localize_only_ = false;
  LoadedMapRelocalizer loaded_map_relocalizer_;  // without places only
  std::unique_ptr<PlaceIndex> places_;           // with a vocabulary only
  std::uint64_t seen_corrections_ = 0;
  int seen_marker_corrections_ = 0;  // anchoring's drift corrections FollowMapCorrections saw
};

}  // namespace arucoslam
