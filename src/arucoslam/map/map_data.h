// MapData: the keyframes, map points and covisibility graph of a map with consistent
// observation bookkeeping. Not thread-safe: reach it through Map::Read / Map::Write (map.h).
#pragma once

#include <map>
#include <vector>

#include "arucoslam/map/covisibility_graph.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/map/indexed_map.h"
#include "arucoslam/map/map_point.h"
#include "arucoslam/util/ids.h"

namespace arucoslam {

// New ids of another map's keyframes and points after MapData::Absorb.
struct AbsorbedIds {
  std::map<KeyframeId, KeyframeId> keyframes;  // other's id -> id in this map
  std::map<MapPointId, MapPointId> points;
};

// Invariants kept by every mutating method:
//  - keyframe.map_point_ids[i] == p  <=>  points[p].observations[keyframe.id] == i;
//  - the covisibility weight of a-b equals the number of points observed by both;
//  - every keyframe but the first has a spanning-tree parent.
class MapData {
 public:
  // Stores a keyframe and returns its new id. Its valid map_point_ids become observations
  // (ids of unknown points, or of points the keyframe would observe twice, are cleared).
  // Spanning-tree parent: the strongest covisible keyframe, else `parent_hint`, else the
  // latest keyframe; none for the first.
  KeyframeId AddKeyframe(Keyframe keyframe, KeyframeId parent_hint = KeyframeId());
  // Stores a point (its observations are ignored: add them with AddObservation).
  MapPointId AddMapPoint(MapPoint point);

  // Point `point` is observed by keypoint `keypoint_index` of `keyframe`. A point the slot
  // held before, or another keypoint of this keyframe observing `point`, is detached first.
  // Returns false for unknown ids or an index out of range.
  bool AddObservation(KeyframeId keyframe, int keypoint_index, MapPointId point);
  // Removes the observation of `point` by `keyframe` (no-op when absent).
  void EraseObservation(KeyframeId keyframe, MapPointId point);
  // Removes a point and all its observations.
  void EraseMapPoint(MapPointId point);
  // Removes a keyframe, its observations and edges; re-parents its children. Points left
  // with no observation are erased too. Returns false for an unknown id or the first keyframe.
  bool EraseKeyframe(KeyframeId keyframe);
  // Fusion of duplicates: every observation of `duplicate` moves to `keep` (unless that
  // keyframe already observes `keep`), the counters add up, `duplicate` is erased.
  void ReplaceMapPoint(MapPointId duplicate, MapPointId keep);

  // Map merging: every keyframe and point of `other` (already in this map's frame) is added
  // under new ids with its observations (and so its covisibility); its spanning tree comes
  // along, its root under `attach_to` (a keyframe of this map). First and last keyframes stay
  // this map's. Nothing changes and false is returned when `attach_to` is unknown.
  bool Absorb(const MapData& other, KeyframeId attach_to, AbsorbedIds* ids);

  void SetKeyframePose(KeyframeId keyframe, const Rigid3& cam_from_world);
  // A refined calibration: every keyframe takes `camera` and its keypoints are undistorted
  // again with it.
  void RecalibrateKeyframes(const CameraModel& camera);
  void SetMapPointPosition(MapPointId point, const Eigen::Vector3d& p_in_world);
  // Recomputes the representative descriptor (least median Hamming distance).
  void UpdateDescriptor(MapPointId point);
  // Recomputes the normal and the scale-invariance distance range from the observations.
  void UpdateNormalAndDepth(MapPointId point);
  void IncreaseVisible(MapPointId point, int n = 1);
  void IncreaseFound(MapPointId point, int n = 1);
  // Re-attaches `child` under `parent` in the spanning tree (restoring a saved map, loop
  // closing). Returns false, changing nothing, for unknown ids or when it would make a cycle.
  bool SetSpanningTreeParent(KeyframeId child, KeyframeId parent) {
    return graph_.SetParent(child, parent);
  }

  const Keyframe* FindKeyframe(KeyframeId id) const;
  const MapPoint* FindMapPoint(MapPointId id) const;
  const std::map<KeyframeId, Keyframe>& keyframes() const { return keyframes_.map(); }
  const std::map<MapPointId, MapPoint>& map_points() const { return points_.map(); }
  const CovisibilityGraph& covisibility() const { return graph_; }
  std::size_t NumKeyframes() const { return keyframes_.size(); }
  std::size_t NumMapPoints() const { return points_.size(); }
  KeyframeId FirstKeyframe() const { return first_keyframe_; }
  KeyframeId LastKeyframe() const { return last_keyframe_; }
  // Points observed by a keyframe (valid, distinct ids in keypoint order).
  std::vector<MapPointId> MapPointsOf(KeyframeId keyframe) const;

  // Checks every invariant above; returns an empty string when all hold, else the first
  // violation found. For tests and debug builds: it walks the whole map.
  std::string CheckInvariants() const;

 private:
  Keyframe* MutableKeyframe(KeyframeId id);
  MapPoint* MutableMapPoint(MapPointId id);

  IndexedMap<KeyframeId, Keyframe> keyframes_;
  IndexedMap<MapPointId, MapPoint> points_;
  CovisibilityGraph graph_;
  IdGenerator<KeyframeId> keyframe_ids_;
  IdGenerator<MapPointId> point_ids_;
  KeyframeId first_keyframe_;
  KeyframeId last_keyframe_;
};

}  // namespace arucoslam
