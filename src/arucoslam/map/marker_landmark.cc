#include "arucoslam/map/marker_landmark.h"

#include <utility>

namespace arucoslam {

std::array<Eigen::Vector3d, 4> MarkerLandmark::CornersInMarker() const {
  return ToMarkerInfo().CornersInMarker();
}

std::array<Eigen::Vector3d, 4> MarkerLandmark::CornersInWorld() const {
  std::array<Eigen::Vector3d, 4> corners = CornersInMarker();
  for (Eigen::Vector3d& corner : corners) corner = world_from_marker * corner;
  return corners;
}

MarkerInfo MarkerLandmark::ToMarkerInfo() const {
  MarkerInfo info;
  info.id = id.value;
  info.size = size;
  info.world_from_marker = world_from_marker;
  info.fixed = fixed;
  return info;
}

MarkerLandmark MarkerLandmark::FromMarkerInfo(const MarkerInfo& info) {
  MarkerLandmark landmark;
  landmark.id = MarkerId(info.id);
  landmark.size = info.size;
  landmark.world_from_marker = info.world_from_marker;
  landmark.fixed = info.fixed;
  return landmark;
}

bool MarkerLandmarks::Add(MarkerLandmark landmark) {
  if (!landmark.id.IsValid() || !(landmark.size > 0.0) || Contains(landmark.id)) return false;
  const MarkerId id = landmark.id;
  landmarks_.emplace(id, std::move(landmark));
  return true;
}

bool MarkerLandmarks::AddObservation(MarkerId id, KeyframeId keyframe,
                                     const std::array<Eigen::Vector2d, 4>& corners_px) {
  const auto it = landmarks_.find(id);
  if (it == landmarks_.end() || !keyframe.IsValid()) return false;
  it->second.observations[keyframe] = corners_px;
  return true;
}

int MarkerLandmarks::EraseKeyframe(KeyframeId keyframe) {
  int count = 0;
  for (auto& [id, landmark] : landmarks_) {
    count += static_cast<int>(landmark.observations.erase(keyframe));
  }
  return count;
}

bool MarkerLandmarks::Erase(MarkerId id) { return landmarks_.erase(id) > 0; }

bool MarkerLandmarks::SetPose(MarkerId id, const Rigid3& world_from_marker) {
  const auto it = landmarks_.find(id);
  if (it == landmarks_.end() || it->second.fixed) return false;
  it->second.world_from_marker = world_from_marker;
  return true;
}

const MarkerLandmark* MarkerLandmarks::Find(MarkerId id) const {
  const auto it = landmarks_.find(id);
  return it == landmarks_.end() ? nullptr : &it->second;
}

MarkerLandmarks MarkerLandmarks::FromMarkerMap(const MarkerMap& map) {
  MarkerLandmarks landmarks;
  for (const auto& [id, info] : map.markers) landmarks.Add(MarkerLandmark::FromMarkerInfo(info));
  return landmarks;
}

MarkerMap MarkerLandmarks::ToMarkerMap(const std::string& dictionary) const {
  MarkerMap map;
  map.dictionary = dictionary;
  for (const auto& [id, landmark] : landmarks_) map.markers[id.value] = landmark.ToMarkerInfo();
  return map;
}

}  // namespace arucoslam
