// LocalMapper::FuseDuplicates: the new keyframe's points are projected into its covisible
// keyframes and theirs into it; a match on a keypoint that already has a point merges the two
// (the one with more observations is kept), a match on a free keypoint adds an observation.
#include <algorithm>
#include <vector>

#include "arucoslam/feature/feature_grid.h"
#include "arucoslam/slam/local_mapper.h"
#include "arucoslam/slam/projection_queries.h"

namespace arucoslam {
namespace {

struct FuseAction {
  KeyframeId target;
  int index = 0;
  MapPointId point;     // the projected point
  MapPointId existing;  // the point the target keypoint held when matched (may be invalid)
};

// Matches `points` projected into `target`; appends one action per accepted match.
void ProjectAndMatch(const MapData& data, const Keyframe& target,
                     const std::vector<MapPointId>& points, const LocalMapperOptions& options,
                     std::vector<FuseAction>* actions) {
  const ProjectionQueries set = UnobservedPointQueries(data, target, target.cam_from_world,
                                                        target.CameraCenter(), points);
  if (set.queries.empty()) return;
  ProjectionMatchOptions match_options;
  match_options.base_radius_px = options.fusion_radius_px;
  match_options.max_distance = options.fusion_max_distance;
  match_options.ratio = 1.0;
  const FeatureGrid grid(target.features);
  for (const FeatureMatch& match :
       MatchByProjection(target.features, grid, set.queries, {}, match_options)) {
    // Reprojection test against the keypoint (distorted pixels, as projected).
    const cv::Point2f& keypoint = target.features.keypoints[match.index2].pt;
    const double sigma = target.SigmaPx(match.index2);
    const Eigen::Vector2d error =
        set.queries[match.index1].pixel - Eigen::Vector2d(keypoint.x, keypoint.y);
    if (error.squaredNorm() > options.reprojection_chi2 * sigma * sigma) continue;
    actions->push_back({target.id, match.index2, set.point_ids[match.index1],
                        target.map_point_ids[match.index2]});
  }
}

}  // namespace

int LocalMapper::FuseDuplicates(KeyframeId keyframe) {
  std::vector<FuseAction> actions;
  map_.Read([&](const MapData& data) {
    const Keyframe* current = data.FindKeyframe(keyframe);
    if (current == nullptr) return;
    const std::vector<MapPointId> own_points = data.MapPointsOf(keyframe);
    std::vector<MapPointId> their_points;
    for (const KeyframeId& id :
         data.covisibility().BestCovisible(keyframe, options_.fusion_neighbours)) {
      const Keyframe& target = *data.FindKeyframe(id);
      ProjectAndMatch(data, target, own_points, options_, &actions);
      const std::vector<MapPointId> points = data.MapPointsOf(id);
      their_points.insert(their_points.end(), points.begin(), points.end());
    }
    std::sort(their_points.begin(), their_points.end());
    their_points.erase(std::unique(their_points.begin(), their_points.end()), their_points.end());
    ProjectAndMatch(data, *current, their_points, options_, &actions);
  });
  return map_.Write([&](MapData& data) {
    int fused = 0;
    for (const FuseAction& action : actions) {
      const Keyframe* target = data.FindKeyframe(action.target);
      const MapPoint* point = data.FindMapPoint(action.point);
      if (target == nullptr || point == nullptr) continue;
      const MapPointId now = target->map_point_ids[action.index];
      if (now != action.existing || now == action.point) continue;
      if (point->observations.count(action.target) != 0) continue;
      if (!now.IsValid()) {
        data.AddObservation(action.target, action.index, action.point);
        ++fused;
        continue;
      }
      const MapPoint* other = data.FindMapPoint(now);
      if (other == nullptr) continue;
      if (other->NumObservations() >= point->NumObservations()) {
        data.ReplaceMapPoint(action.point, now);
      } else {
        data.ReplaceMapPoint(now, action.point);
      }
      ++fused;
    }
    for (const MapPointId& id : data.MapPointsOf(keyframe)) {
      data.UpdateDescriptor(id);
      data.UpdateNormalAndDepth(id);
    }
    return fused;
  });
}

}  // namespace arucoslam
