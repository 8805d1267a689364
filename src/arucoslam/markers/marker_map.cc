#include "arucoslam/markers/marker_map.h"

namespace arucoslam {

std::array<Eigen::Vector3d, 4> MarkerInfo::CornersInMarker() const {
  const double half = 0.5 * size;
  return {Eigen::Vector3d(-half, half, 0.0), Eigen::Vector3d(half, half, 0.0),
          Eigen::Vector3d(half, -half, 0.0), Eigen::Vector3d(-half, -half, 0.0)};
}

std::array<Eigen::Vector3d, 4> MarkerInfo::CornersInWorld() const {
  std::array<Eigen::Vector3d, 4> corners = CornersInMarker();
  for (Eigen::Vector3d& corner : corners) corner = world_from_marker * corner;
  return corners;
}

}  // namespace arucoslam
