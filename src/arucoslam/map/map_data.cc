#include "arucoslam/map/map_data.h"

#include <fmt/format.h>

#include <set>

#include "arucoslam/feature/undistort.h"

namespace arucoslam {

Keyframe* MapData::MutableKeyframe(KeyframeId id) { return keyframes_.Find(id); }

MapPoint* MapData::MutableMapPoint(MapPointId id) { return points_.Find(id); }

const Keyframe* MapData::FindKeyframe(KeyframeId id) const { return keyframes_.Find(id); }

const MapPoint* MapData::FindMapPoint(MapPointId id) const { return points_.Find(id); }

KeyframeId MapData::AddKeyframe(Keyframe keyframe, KeyframeId parent_hint) {
  const KeyframeId id = keyframe_ids_.Next();
  keyframe.id = id;
  std::vector<MapPointId> wanted = std::move(keyframe.map_point_ids);
  keyframe.map_point_ids.assign(keyframe.features.size(), MapPointId());
  const std::size_t num_keypoints = keyframes_.Emplace(id, std::move(keyframe)).map_point_ids.size();
  graph_.AddKeyframe(id);
  for (std::size_t i = 0; i < wanted.size() && i < num_keypoints; ++i) {
    const MapPoint* point = FindMapPoint(wanted[i]);
    if (point == nullptr || point->observations.count(id) != 0) continue;
    AddObservation(id, static_cast<int>(i), wanted[i]);
  }
  std::vector<KeyframeId> best = graph_.BestCovisible(id, 1);
  KeyframeId parent;
  if (!best.empty()) {
    parent = best.front();
  } else if (parent_hint.IsValid() && graph_.Contains(parent_hint) && parent_hint != id) {
    parent = parent_hint;
  } else {
    parent = last_keyframe_;
  }
  if (parent.IsValid()) graph_.SetParent(id, parent);
  if (!first_keyframe_.IsValid()) first_keyframe_ = id;
  last_keyframe_ = id;
  return id;
}

bool MapData::Absorb(const MapData& other, KeyframeId attach_to, AbsorbedIds* ids) {
  if (!graph_.Contains(attach_to)) return false;
  *ids = AbsorbedIds();
  for (const auto& [old_id, source] : other.keyframes_.map()) {
    Keyframe keyframe = source;
    const KeyframeId id = keyframe_ids_.Next();
    keyframe.id = id;
    keyframe.map_point_ids.assign(keyframe.features.size(), MapPointId());
    keyframes_.Emplace(id, std::move(keyframe));
    graph_.AddKeyframe(id);
    ids->keyframes[old_id] = id;
  }
  for (const auto& [old_id, source] : other.points_.map()) {
    const MapPointId id = AddMapPoint(source);
    ids->points[old_id] = id;
    for (const auto& [keyframe, index] : source.observations) {
      AddObservation(ids->keyframes.at(keyframe), index, id);
    }
    // The reference is an id of `other`: the same number may name a keyframe of this map,
    // whose corrections the point would then follow.
    MapPoint& point = *points_.Find(id);
    const auto reference = ids->keyframes.find(source.reference_keyframe);
    if (reference != ids->keyframes.end()) {
      point.reference_keyframe = reference->second;
    } else {
      point.reference_keyframe =
          point.observations.empty() ? KeyframeId() : point.observations.begin()->first;
    }
  }
  for (const auto& [old_id, id] : ids->keyframes) {
    const KeyframeId old_parent = other.graph_.Parent(old_id);
    graph_.SetParent(id, old_parent.IsValid() ? ids->keyframes.at(old_parent) : attach_to);
  }
  return true;
}

MapPointId MapData::AddMapPoint(MapPoint point) {
  const MapPointId id = point_ids_.Next();
  point.id = id;
  point.observations.clear();
  points_.Emplace(id, std::move(point));
  return id;
}

bool MapData::AddObservation(KeyframeId keyframe_id, int keypoint_index, MapPointId point_id) {
  Keyframe* keyframe = MutableKeyframe(keyframe_id);
  MapPoint* point = MutableMapPoint(point_id);
  if (keyframe == nullptr || point == nullptr || keypoint_index < 0 ||
      keypoint_index >= static_cast<int>(keyframe->map_point_ids.size())) {
    return false;
  }
  const MapPointId previous = keyframe->map_point_ids[keypoint_index];
  if (previous == point_id) return true;
  if (previous.IsValid()) EraseObservation(keyframe_id, previous);
  EraseObservation(keyframe_id, point_id);  // the point seen by another keypoint before
  for (const auto& [other, index] : point->observations) graph_.AddToWeight(keyframe_id, other, 1);
  point->observations[keyframe_id] = keypoint_index;
  keyframe->map_point_ids[keypoint_index] = point_id;
  return true;
}

void MapData::EraseObservation(KeyframeId keyframe_id, MapPointId point_id) {
  MapPoint* point = MutableMapPoint(point_id);
  if (point == nullptr) return;
  const auto it = point->observations.find(keyframe_id);
  if (it == point->observations.end()) return;
  Keyframe* keyframe = MutableKeyframe(keyframe_id);
  if (keyframe != nullptr) keyframe->map_point_ids[it->second] = MapPointId();
  point->observations.erase(it);
  for (const auto& [other, index] : point->observations) {
    graph_.AddToWeight(keyframe_id, other, -1);
  }
  if (point->reference_keyframe == keyframe_id) {
    point->reference_keyframe =
        point->observations.empty() ? KeyframeId() : point->observations.begin()->first;
  }
}

void MapData::EraseMapPoint(MapPointId point_id) {
  MapPoint* point = MutableMapPoint(point_id);
  if (point == nullptr) return;
  while (!point->observations.empty()) {
    EraseObservation(point->observations.begin()->first, point_id);
  }
  points_.Erase(point_id);
}

bool MapData::EraseKeyframe(KeyframeId keyframe_id) {
  Keyframe* keyframe = MutableKeyframe(keyframe_id);
  if (keyframe == nullptr || keyframe_id == first_keyframe_) return false;
  const std::vector<MapPointId> observed = MapPointsOf(keyframe_id);
  for (const MapPointId& point_id : observed) {
    EraseObservation(keyframe_id, point_id);
    const MapPoint* point = FindMapPoint(point_id);
    if (point != nullptr && point->observations.empty()) points_.Erase(point_id);
  }
  graph_.RemoveKeyframe(keyframe_id);
  keyframes_.Erase(keyframe_id);
  if (last_keyframe_ == keyframe_id) last_keyframe_ = keyframes_.map().rbegin()->first;
  return true;
}

void MapData::ReplaceMapPoint(MapPointId duplicate_id, MapPointId keep_id) {
  if (duplicate_id == keep_id) return;
  MapPoint* duplicate = MutableMapPoint(duplicate_id);
  MapPoint* keep = MutableMapPoint(keep_id);
  if (duplicate == nullptr || keep == nullptr) return;
  const std::map<KeyframeId, int> moved = duplicate->observations;
  keep->num_visible += duplicate->num_visible;
  keep->num_found += duplicate->num_found;
  EraseMapPoint(duplicate_id);
  for (const auto& [keyframe_id, index] : moved) {
    if (keep->observations.count(keyframe_id) == 0) AddObservation(keyframe_id, index, keep_id);
  }
  UpdateDescriptor(keep_id);
}

void MapData::SetKeyframePose(KeyframeId id, const Rigid3& cam_from_world) {
  if (Keyframe* keyframe = MutableKeyframe(id)) keyframe->cam_from_world = cam_from_world;
}

void MapData::SetMapPointPosition(MapPointId id, const Eigen::Vector3d& p_in_world) {
  if (MapPoint* point = MutableMapPoint(id)) point->p_in_world = p_in_world;
}

void MapData::IncreaseVisible(MapPointId id, int n) {
  if (MapPoint* point = MutableMapPoint(id)) point->num_visible += n;
}

void MapData::IncreaseFound(MapPointId id, int n) {
  if (MapPoint* point = MutableMapPoint(id)) point->num_found += n;
}

void MapData::UpdateDescriptor(MapPointId id) {
  MapPoint* point = MutableMapPoint(id);
  if (point == nullptr || point->observations.empty()) return;
  std::vector<const std::uint8_t*> descriptors;
  for (const auto& [keyframe_id, index] : point->observations) {
    const Keyframe* keyframe = FindKeyframe(keyframe_id);
    if (keyframe != nullptr && index < keyframe->features.descriptors.rows) {
      descriptors.push_back(keyframe->features.Descriptor(index));
    }
  }
  const int best = MedianDescriptorIndex(descriptors);
  if (best >= 0) std::copy_n(descriptors[best], kOrbDescriptorBytes, point->descriptor.begin());
}

void MapData::RecalibrateKeyframes(const CameraModel& camera) {
  keyframes_.ForEachMutable([&](KeyframeId, Keyframe& keyframe) {
    keyframe.camera = camera;
    UndistortFeatures(camera, &keyframe.features);
  });
}

void MapData::UpdateNormalAndDepth(MapPointId id) {
  MapPoint* point = MutableMapPoint(id);
  if (point == nullptr || point->observations.empty()) return;
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  for (const auto& [keyframe_id, index] : point->observations) {
    const Keyframe* keyframe = FindKeyframe(keyframe_id);
    const Eigen::Vector3d ray = point->p_in_world - keyframe->CameraCenter();
    if (ray.norm() > 0.0) normal_sum += ray.normalized();
  }
  if (normal_sum.norm() > 0.0) point->normal = normal_sum.normalized();
  KeyframeId reference = point->reference_keyframe;
  if (point->observations.count(reference) == 0) reference = point->observations.begin()->first;
  const Keyframe* keyframe = FindKeyframe(reference);
  const double distance = (point->p_in_world - keyframe->CameraCenter()).norm();
  const ScalePyramid& pyramid = keyframe->features.pyramid;
  const int level = keyframe->features.keypoints[point->observations.at(reference)].octave;
  const bool has_scales =
      !pyramid.scales.empty() && level >= 0 && level < static_cast<int>(pyramid.scales.size());
  point->max_distance = distance * (has_scales ? pyramid.scales[level] : 1.0);
  point->min_distance = point->max_distance / (has_scales ? pyramid.scales.back() : 1.0);
}

std::vector<MapPointId> MapData::MapPointsOf(KeyframeId id) const {
  std::vector<MapPointId> result;
  const Keyframe* keyframe = FindKeyframe(id);
  if (keyframe == nullptr) return result;
  for (const MapPointId& point : keyframe->map_point_ids) {
    if (point.IsValid()) result.push_back(point);
  }
  return result;
}

}  // namespace arucoslam
