// ProjectionQueries: map points projected into a frame, as queries for MatchByProjection,
// with the ids of their points and descriptor copies that stay valid while matching.
#pragma once

#include <vector>

#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/map/frame.h"
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

}  // namespace arucoslam
