#include "arucoslam/optim/local_bundle_adjustment.h"

#include <algorithm>
#include <map>
#include <set>
#include <vector>

namespace arucoslam {
namespace {

// The problem plus the ids behind its indices.
struct Snapshot {
  BundleAdjustmentProblem problem;
  std::vector<KeyframeId> keyframe_ids;  // per problem pose
  std::vector<MapPointId> point_ids;     // per problem point
  std::vector<int> keypoint_indices;     // per observation
  // Observations left out as too near their keyframe: (keyframe, point, keypoint index).
  struct Excluded {
    KeyframeId keyframe;
    MapPointId point;
    int index = 0;
  };
  std::vector<Excluded> too_near;
  int num_local = 0;
  int num_fixed = 0;
};

// Every border keyframe is fixed; `border` maps each to the number of window points it
// observes. Window keyframes are added (oldest first) until min_fixed_keyframes fixed ones
// are anchors (see min_anchor_points); the map's first keyframe always is one.
std::set<KeyframeId> ChooseFixed(const MapData& data, KeyframeId current,
                                 const std::vector<KeyframeId>& local,
                                 const std::map<KeyframeId, int>& border,
                                 const LocalBundleAdjustmentOptions& options) {
  std::set<KeyframeId> fixed;
  int anchors = 0;
  for (const auto& [id, shared] : border) {
    fixed.insert(id);
    if (shared >= options.min_anchor_points) ++anchors;
  }
  std::set<KeyframeId> local_sorted(local.begin(), local.end());
  if (local_sorted.count(data.FirstKeyframe()) != 0) {
    fixed.insert(data.FirstKeyframe());
    ++anchors;
  }
  for (const KeyframeId& id : local_sorted) {
    if (anchors >= options.min_fixed_keyframes) break;
    if (id != current && fixed.insert(id).second) ++anchors;
  }
  if (anchors < options.min_fixed_keyframes) fixed.insert(current);
  return fixed;
}

// Median depth of the points a keyframe observes (0 when it has none).
double MedianPointDepth(const MapData& data, const Keyframe& keyframe) {
  std::vector<double> depths;
  for (const MapPointId& id : keyframe.map_point_ids) {
    if (const MapPoint* point = data.FindMapPoint(id)) {
      depths.push_back((keyframe.cam_from_world * point->p_in_world).z());
    }
  }
  if (depths.empty()) return 0.0;
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  return depths[depths.size() / 2];
}

Snapshot TakeSnapshot(const MapData& data, KeyframeId current,
                      const LocalBundleAdjustmentOptions& options) {
  Snapshot snapshot;
  const Keyframe* keyframe = data.FindKeyframe(current);
  if (keyframe == nullptr) return snapshot;
  std::vector<KeyframeId> local = {current};
  for (const KeyframeId& id :
       data.covisibility().BestCovisible(current, options.max_covisible_keyframes)) {
    local.push_back(id);
  }
  // The window's points in id order, each looked up once.
  std::vector<MapPointId> point_ids;
  for (const KeyframeId& id : local) {
    const std::vector<MapPointId> observed = data.MapPointsOf(id);
    point_ids.insert(point_ids.end(), observed.begin(), observed.end());
  }
  std::sort(point_ids.begin(), point_ids.end());
  point_ids.erase(std::unique(point_ids.begin(), point_ids.end()), point_ids.end());
  std::vector<const MapPoint*> points;
  points.reserve(point_ids.size());
  for (const MapPointId& id : point_ids) points.push_back(data.FindMapPoint(id));

  const std::set<KeyframeId> local_set(local.begin(), local.end());
  std::map<KeyframeId, int> border_points;  // border keyframe -> window points it observes
  for (const MapPoint* point : points) {
    for (const auto& [observer, index] : point->observations) {
      if (local_set.count(observer) == 0) ++border_points[observer];
    }
  }
  std::set<KeyframeId> border;
  for (const auto& [id, count] : border_points) border.insert(id);
  const std::set<KeyframeId> fixed = ChooseFixed(data, current, local, border_points, options);

  snapshot.problem.intrinsics = PinholeIntrinsics::FromCamera(keyframe->camera);
  // Per observer: its problem pose, its keyframe, and min_relative_depth x its median depth.
  struct Observer {
    std::size_t pose_index = 0;
    const Keyframe* keyframe = nullptr;
    double min_depth = 0.0;
  };
  std::map<KeyframeId, Observer> observers;
  for (const std::set<KeyframeId>* group :
       std::vector<const std::set<KeyframeId>*>{&local_set, &border}) {
    for (const KeyframeId& id : *group) {
      const Keyframe* observer = data.FindKeyframe(id);
      observers[id] = {snapshot.problem.poses.size(), observer, 0.0};
      snapshot.problem.poses.push_back({observer->cam_from_world, fixed.count(id) != 0});
      snapshot.keyframe_ids.push_back(id);
    }
  }
  for (auto& [id, observer] : observers) {
    observer.min_depth = options.min_relative_depth * MedianPointDepth(data, *observer.keyframe);
  }
  std::vector<std::pair<const Observer*, int>> kept;
  for (std::size_t p = 0; p < points.size(); ++p) {
    const MapPoint* point = points[p];
    kept.clear();
    for (const auto& [observer_id, index] : point->observations) {
      const Observer& observer = observers.at(observer_id);
      const double depth = (observer.keyframe->cam_from_world * point->p_in_world).z();
      if (depth <= 0.0 || depth < observer.min_depth) {
        snapshot.too_near.push_back({observer_id, point_ids[p], index});
      } else {
        kept.emplace_back(&observer, index);
      }
    }
    if (kept.empty()) continue;
    const std::size_t point_index = snapshot.problem.points.size();
    // One view cannot place a point (its depth is free): it is held, constraining the pose.
    snapshot.problem.points.push_back({point->p_in_world, kept.size() < 2});
    snapshot.point_ids.push_back(point_ids[p]);
    for (const auto& [observer, index] : kept) {
      snapshot.problem.observations.push_back({observer->pose_index, point_index,
                                               observer->keyframe->UndistortedPixel(index),
                                               observer->keyframe->SigmaPx(index)});
      snapshot.keypoint_indices.push_back(index);
    }
  }
  snapshot.num_local = static_cast<int>(local_set.size());
  snapshot.num_fixed = static_cast<int>(fixed.size());
  return snapshot;
}

int WriteBack(MapData& data, const Snapshot& snapshot, const BundleAdjustmentSummary& summary,
              bool erase_outliers) {
  const BundleAdjustmentProblem& problem = snapshot.problem;
  for (std::size_t i = 0; i < problem.poses.size(); ++i) {
    if (!problem.poses[i].fixed) {
      data.SetKeyframePose(snapshot.keyframe_ids[i], problem.poses[i].cam_from_world);
    }
  }
  int erased = 0;
  if (erase_outliers) {
    for (const Snapshot::Excluded& excluded : snapshot.too_near) {
      const MapPoint* point = data.FindMapPoint(excluded.point);
      if (point == nullptr) continue;
      const auto it = point->observations.find(excluded.keyframe);
      if (it == point->observations.end() || it->second != excluded.index) continue;
      data.EraseObservation(excluded.keyframe, excluded.point);
      if (data.FindMapPoint(excluded.point)->observations.empty()) {
        data.EraseMapPoint(excluded.point);
      }
      ++erased;
    }
    for (std::size_t k = 0; k < problem.observations.size(); ++k) {
      if (!summary.outliers[k]) continue;
      const KeyframeId keyframe_id = snapshot.keyframe_ids[problem.observations[k].pose_index];
      const MapPointId point_id = snapshot.point_ids[problem.observations[k].point_index];
      const MapPoint* point = data.FindMapPoint(point_id);
      if (point == nullptr) continue;
      const auto it = point->observations.find(keyframe_id);
      if (it == point->observations.end() || it->second != snapshot.keypoint_indices[k]) continue;
      data.EraseObservation(keyframe_id, point_id);
      ++erased;
    }
  }
  for (std::size_t j = 0; j < problem.points.size(); ++j) {
    const MapPointId point_id = snapshot.point_ids[j];
    const MapPoint* point = data.FindMapPoint(point_id);
    if (point == nullptr) continue;
    if (point->observations.empty()) {
      data.EraseMapPoint(point_id);
      continue;
    }
    data.SetMapPointPosition(point_id, problem.points[j].p_in_world);
    data.UpdateNormalAndDepth(point_id);
  }
  return erased;
}

}  // namespace

LocalBundleAdjustmentResult RunLocalBundleAdjustment(Map& map, KeyframeId keyframe,
                                                     const LocalBundleAdjustmentOptions& options,
                                                     MarkerLandmarks* markers) {
  LocalBundleAdjustmentResult result;
  MarkerFactors factors;
  Snapshot snapshot = map.Read([&](const MapData& data) {
    Snapshot taken = TakeSnapshot(data, keyframe, options);
    if (markers != nullptr) {
      factors = CollectMarkerFactors(data, taken.keyframe_ids, *markers, options.markers);
    }
    return taken;
  });
  result.num_marker_observations = static_cast<int>(factors.observations.size());
  result.num_local_keyframes = snapshot.num_local;
  result.num_fixed_keyframes = snapshot.num_fixed;
  result.num_points = static_cast<int>(snapshot.problem.points.size());
  result.num_too_near_observations = static_cast<int>(snapshot.too_near.size());
  if (snapshot.problem.observations.empty()) {
    result.summary.message = "no observations in the local window";
    return result;
  }
  result.summary = SolveBundleAdjustmentWithMarkers(options.solver, options.markers, &factors,
                                                    &snapshot.problem);
  if (!result.summary.success) return result;
  if (markers != nullptr) result.num_moved_markers = ApplyMarkerFactors(factors, markers);
  result.num_erased_observations = map.Write([&](MapData& data) {
    return WriteBack(data, snapshot, result.summary, options.erase_outliers);
  });
  result.applied = true;
  return result;
}

}  // namespace arucoslam
