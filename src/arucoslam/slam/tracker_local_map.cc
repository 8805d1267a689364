// Tracker::TrackLocalMap: the local keyframes (those observing the frame's matches and their
// best covisible neighbours), their points projected into the frame and matched, then the
// final pose optimisation.
#include <algorithm>
#include <cstdint>
#include <set>
#include <unordered_map>
#include <vector>

#include "arucoslam/feature/feature_grid.h"
#include "arucoslam/slam/projection_queries.h"
#include "arucoslam/slam/tracker.h"

namespace arucoslam {
namespace {

// Keyframes observing `voters` (the frame's matched points), most votes first, then best covisible
// neighbours of each; the first one is the frame's natural reference keyframe.
std::vector<KeyframeId> LocalKeyframes(const MapData& data, const std::vector<MapPointId>& voters,
                                       const TrackerOptions& options) {
  std::unordered_map<KeyframeId, int> votes;
  for (const MapPointId& id : voters) {
    if (const MapPoint* point = data.FindMapPoint(id)) {
      for (const auto& [keyframe, index] : point->observations) ++votes[keyframe];
    }
  }
  std::vector<std::pair<int, KeyframeId>> sorted;
  for (const auto& [keyframe, count] : votes) sorted.emplace_back(-count, keyframe);
  std::sort(sorted.begin(), sorted.end());
  std::vector<KeyframeId> local;
  std::set<KeyframeId> included;
  for (const auto& entry : sorted) {
    if (static_cast<int>(local.size()) >= options.max_local_keyframes) break;
    local.push_back(entry.second);
    included.insert(entry.second);
  }
  const std::size_t num_direct = local.size();
  for (std::size_t k = 0; k < num_direct; ++k) {
    for (const KeyframeId& neighbour :
         data.covisibility().BestCovisible(local[k], options.covisible_per_keyframe)) {
      if (static_cast<int>(local.size()) >= options.max_local_keyframes) return local;
      if (included.insert(neighbour).second) local.push_back(neighbour);
    }
  }
  return local;
}

// Marks on map point ids (dense integers from the map's IdGenerator): a set with constant-time
// insertion that clears in the time of its insertions. One per thread, reused across frames.
class PointMarks {
 public:
  // True when `id` was not marked yet (it is now).
  bool Insert(MapPointId id) {
    if (id.value >= marked_.size()) marked_.resize(id.value + 1 + id.value / 2, 0);
    if (marked_[id.value] != 0) return false;
    marked_[id.value] = 1;
    inserted_.push_back(id.value);
    return true;
  }
  void Clear() {
    for (const auto value : inserted_) marked_[value] = 0;
    inserted_.clear();
  }

 private:
  std::vector<std::uint8_t> marked_;
  std::vector<MapPointId::ValueType> inserted_;
};

// Projects the local points that the frame has not matched yet; returns the queries and
// (through `visible`) every point predicted in view, matched ones included.
ProjectionQueries LocalPointQueries(const MapData& data, const Frame& frame,
                                    const std::vector<KeyframeId>& local,
                                    const TrackerOptions& options, double radius_factor,
                                    std::vector<MapPointId>* visible) {
  // Points already matched or already considered: skipped.
  thread_local PointMarks done;
  done.Clear();
  for (const MapPointId& id : frame.map_point_ids) {
    if (id.IsValid()) {
      done.Insert(id);
      visible->push_back(id);
    }
  }
  const Rigid3& cam_from_world = *frame.cam_from_world;
  const Eigen::Vector3d center = cam_from_world.Inverse().translation;
  ProjectionQueries set;
  for (const KeyframeId& keyframe : local) {
    for (const MapPointId& id : data.FindKeyframe(keyframe)->map_point_ids) {
      if (!id.IsValid() || !done.Insert(id)) continue;
      const MapPoint& point = *data.FindMapPoint(id);
      const std::optional<Eigen::Vector2d> pixel =
          frame.camera.Project(cam_from_world * point.p_in_world);
      if (!pixel || !frame.camera.InImage(*pixel)) continue;
      const Eigen::Vector3d ray = point.p_in_world - center;
      const double distance = ray.norm();
      if (!point.InDistanceRange(distance)) continue;
      const double view_cos = point.normal.dot(ray) / distance;
      if (view_cos < options.min_view_cos) continue;
      const int level = point.PredictLevel(distance, frame.features.pyramid);
      set.Add(id, *pixel, level, point.descriptor, (view_cos > 0.998 ? 2.5 : 4.0) * radius_factor,
              -1.0f);
      visible->push_back(id);
    }
  }
  set.Finalize();
  return set;
}

}  // namespace

bool Tracker::TrackLocalMap(Frame& frame, TrackingResult& result, double radius_factor,
                            bool allow_weak) {
  std::vector<MapPointId> visible;
  ProjectionQueries set;
  // A frame with no matches yet (pose predicted) takes its local map from the last frame.
  bool has_matches = false;
  for (const MapPointId& id : frame.map_point_ids) has_matches = has_matches || id.IsValid();
  const std::vector<MapPointId>& voters =
      has_matches || !last_frame_ ? frame.map_point_ids : last_frame_->map_point_ids;
  map_.Read([&](const MapData& data) {
    const std::vector<KeyframeId> local = LocalKeyframes(data, voters, options_);
    if (!local.empty()) reference_keyframe_ = local.front();
    set = LocalPointQueries(data, frame, local, options_, radius_factor, &visible);
  });
  std::vector<bool> taken(frame.features.size(), false);
  for (std::size_t i = 0; i < frame.map_point_ids.size(); ++i) {
    taken[i] = frame.map_point_ids[i].IsValid();
  }
  const FeatureGrid grid(frame.features);
  const std::vector<FeatureMatch> matches =
      MatchByProjection(frame.features, grid, set.queries, taken, options_.local_map_search);
  result.num_local_map_matches = set.AssignTo(matches, frame);
  result.num_inliers = OptimizeFramePose(frame, *frame.cam_from_world);
  if (options_.update_point_statistics) {
    map_.Write([&](MapData& data) {
      for (const MapPointId& id : visible) data.IncreaseVisible(id);
      for (const MapPointId& id : frame.map_point_ids) {
        if (id.IsValid()) data.IncreaseFound(id);
      }
    });
  }
  if (result.num_inliers >= options_.min_local_map_inliers) return true;
  if (!allow_weak || result.num_inliers < options_.min_weak_inliers || !frame.cam_from_world) {
    return false;
  }
  const std::optional<int> steps = MotionSteps(frame.timestamp_s);
  return steps && AgreesWithPrediction(*frame.cam_from_world, *steps);
}

}  // namespace arucoslam
