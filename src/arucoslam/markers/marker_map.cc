#include "arucoslam/markers/marker_map.h"

namespace arucoslam {

std::array<Eigen::Vector3d, 4> MarkerInfo::CornersInMarker() const {
  const double half = 0.5 * size;
  return {Eigen::Vector3d(-half, half, 0.0), Eigen::Vector3d(half, half, 0.0),
          Eigen::Vector3d(half, -half, 0.0), Eigen::Vector3d(-half, -half, 0.0)};
}

bool SeesPrintedSide(const Rigid3& world_from_marker, const Eigen::Vector3d& camera_in_world,
                     double min_view_cosine) {
  const Eigen::Vector3d normal = world_from_marker.rotation * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d to_camera = camera_in_world - world_from_marker.translation;
  return normal.dot(to_camera) > min_view_cosine * to_camera.norm();
}

std::array<Eigen::Vector3d, 4> MarkerInfo::CornersInWorld() const {
  std::array<Eigen::Vector3d, 4> corners = CornersInMarker();
  for (Eigen::Vector3d& corner : corners) corner = world_from_marker * corner;
  return corners;
}

}  // namespace arucoslam
