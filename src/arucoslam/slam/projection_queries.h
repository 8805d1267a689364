// ProjectionQueries: map points projected into a frame, as queries for MatchByProjection,
// with the ids of their points and descriptor copies that stay valid while matching.
#pragma once

#include <vector>

#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/map/map_data.h"
#include "arucoslam/map/map_point.h"

namespace arucoslam {

struct ProjectionQueries {
  std::vector<ProjectionQuery> queries;
  std::vector<MapPointId> point_ids;
  std::vector<OrbDescriptor> descriptors;

  void Add(MapPointId id, const Eigen::Vector2d& pixel, int level, const OrbDescriptor& descriptor,
           double radius_factor, float angle) {
    point_ids.push_back(id);
    descriptors.push_back(descriptor);
    queries.push_back({pixel, level, nullptr, radius_factor, angle});
  }
  // Points each query at its descriptor; call once all queries are added.
  void Finalize() {
    for (std::size_t i = 0; i < queries.size(); ++i) queries[i].descriptor = descriptors[i].data();
  }
  // Writes the matches (index1 = query, index2 = keypoint) into frame.map_point_ids where
  // the keypoint has no point yet; returns how many were written.
  int AssignTo(const std::vector<FeatureMatch>& matches, Frame& frame) const {
    int assigned = 0;
    for (const FeatureMatch& match : matches) {
      if (frame.map_point_ids[match.index2].IsValid()) continue;
      frame.map_point_ids[match.index2] = point_ids[match.index1];
      ++assigned;
    }
    return assigned;
  }
};

// Queries for the points of `point_ids` that `target` does not observe yet, projected with
// `cam_from_world` (a Rigid3, or a Sim3 for loop-corrected poses) from `camera_centre`: kept
// when in front, inside the image, within the point's distance range and seen within 60
// degrees of its normal. Angles are unknown (-1: no rotation check). Finalized on return.
template <typename Transform>
ProjectionQueries UnobservedPointQueries(const MapData& data, const Keyframe& target,
                                         const Transform& cam_from_world,
                                         const Eigen::Vector3d& camera_centre,
                                         const std::vector<MapPointId>& point_ids) {
  ProjectionQueries set;
  for (const MapPointId& id : point_ids) {
    const MapPoint* point = data.FindMapPoint(id);
    if (point == nullptr || point->observations.count(target.id) != 0) continue;
    const Eigen::Vector3d p_in_cam = cam_from_world * point->p_in_world;
    if (!(p_in_cam.z() > 0.0)) continue;
    const std::optional<Eigen::Vector2d> pixel = target.camera.Project(p_in_cam);
    if (!pixel || !target.camera.InImage(*pixel)) continue;
    const Eigen::Vector3d ray = point->p_in_world - camera_centre;
    const double distance = ray.norm();
    if (!point->InDistanceRange(distance) || point->normal.dot(ray) < 0.5 * distance) continue;
    set.Add(id, *pixel, point->PredictLevel(distance, target.features.pyramid), point->descriptor,
            1.0, -1.0f);
  }
  set.Finalize();
  return set;
}

}  // namespace arucoslam
