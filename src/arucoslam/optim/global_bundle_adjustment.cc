#include "arucoslam/optim/global_bundle_adjustment.h"

#include <map>
#include <optional>
#include <set>

namespace arucoslam {
namespace {

// world_before_from_world_after of a keyframe via its nearest ancestor in the snapshot.
std::optional<Rigid3> WorldCorrection(const MapData& data,
                                      const std::map<KeyframeId, std::size_t>& pose_index,
                                      const GlobalBundleAdjustmentSnapshot& snapshot,
                                      KeyframeId id) {
  for (std::size_t depth = 0; id.IsValid() && depth <= data.NumKeyframes(); ++depth) {
    const auto it = pose_index.find(id);
    if (it != pose_index.end()) {
      return snapshot.poses_before[it->second].Inverse() *
             snapshot.problem.poses[it->second].cam_from_world;
    }
    id = data.covisibility().Contains(id) ? data.covisibility().Parent(id) : KeyframeId();
  }
  return std::nullopt;
}

int EraseOutliers(MapData& data, const GlobalBundleAdjustmentSnapshot& snapshot,
                  const std::vector<bool>& outliers) {
  int erased = 0;
  const BundleAdjustmentProblem& problem = snapshot.problem;
  for (std::size_t k = 0; k < problem.observations.size(); ++k) {
    if (!outliers[k]) continue;
    const KeyframeId keyframe = snapshot.keyframe_ids[problem.observations[k].pose_index];
    const MapPointId point_id = snapshot.point_ids[problem.observations[k].point_index];
    const MapPoint* point = data.FindMapPoint(point_id);
    if (point == nullptr) continue;
    const auto it = point->observations.find(keyframe);
    if (it == point->observations.end() || it->second != snapshot.keypoint_indices[k]) continue;
    data.EraseObservation(keyframe, point_id);
    ++erased;
  }
  return erased;
}

}  // namespace

GlobalBundleAdjustmentSnapshot TakeGlobalSnapshot(const MapData& data,
                                                  const GlobalBundleAdjustmentOptions& options,
                                                  const MarkerLandmarks* landmarks,
                                                  const std::vector<KeyframePosePrior>& priors) {
  GlobalBundleAdjustmentSnapshot snapshot;
  std::map<KeyframeId, std::size_t> pose_index;
  for (const auto& [id, keyframe] : data.keyframes()) {
    if (snapshot.keyframe_ids.empty()) {
      snapshot.problem.intrinsics = PinholeIntrinsics::FromCamera(keyframe.camera);
    }
    const bool fixed = static_cast<int>(snapshot.keyframe_ids.size()) < options.num_fixed_keyframes;
    pose_index[id] = snapshot.problem.poses.size();
    snapshot.problem.poses.push_back({keyframe.cam_from_world, fixed});
    snapshot.poses_before.push_back(keyframe.cam_from_world);
    snapshot.keyframe_ids.push_back(id);
  }
  for (const auto& [id, point] : data.map_points()) {
    if (point.observations.empty()) continue;
    const std::size_t point_index = snapshot.problem.points.size();
    snapshot.problem.points.push_back({point.p_in_world, false});
    snapshot.point_ids.push_back(id);
    for (const auto& [observer, index] : point.observations) {
      const Keyframe* keyframe = data.FindKeyframe(observer);
      snapshot.problem.observations.push_back({pose_index.at(observer), point_index,
                                               keyframe->UndistortedPixel(index),
                                               keyframe->SigmaPx(index)});
      snapshot.keypoint_indices.push_back(index);
    }
  }
  if (landmarks != nullptr) {
    snapshot.markers =
        CollectMarkerFactors(data, snapshot.keyframe_ids, *landmarks, options.markers);
    if (snapshot.markers.num_fixed_markers > 0) {
      for (auto& pose : snapshot.problem.poses) pose.fixed = false;
    }
  }
  snapshot.markers.position_priors = PositionPriorsOf(priors, snapshot.keyframe_ids);
  return snapshot;
}

BundleAdjustmentSummary SolveGlobalSnapshot(const GlobalBundleAdjustmentOptions& options,
                                            GlobalBundleAdjustmentSnapshot* snapshot) {
  return SolveBundleAdjustmentWithMarkers(options.solver, options.markers, &snapshot->markers,
                                          &snapshot->problem);
}

void ApplyGlobalBundleAdjustment(MapData& data, const GlobalBundleAdjustmentSnapshot& snapshot,
                                 const GlobalBundleAdjustmentOptions& options,
                                 GlobalBundleAdjustmentResult* result,
                                 MarkerLandmarks* landmarks) {
  result->num_marker_observations = static_cast<int>(snapshot.markers.observations.size());
  if (landmarks != nullptr) ApplyMarkerFactors(snapshot.markers, landmarks);
  std::map<KeyframeId, std::size_t> pose_index;
  for (std::size_t i = 0; i < snapshot.keyframe_ids.size(); ++i) {
    pose_index[snapshot.keyframe_ids[i]] = i;
  }
  // Corrections first, from the spanning tree as it is now, before any pose changes.
  std::map<KeyframeId, Rigid3> corrections;
  for (const auto& [id, keyframe] : data.keyframes()) {
    if (auto correction = WorldCorrection(data, pose_index, snapshot, id)) {
      corrections[id] = *correction;
    }
  }
  std::set<MapPointId> solved_points(snapshot.point_ids.begin(), snapshot.point_ids.end());
  std::vector<std::pair<MapPointId, Eigen::Vector3d>> moved;
  for (const auto& [id, point] : data.map_points()) {
    if (solved_points.count(id) != 0) continue;
    KeyframeId reference = point.reference_keyframe;
    if (corrections.count(reference) == 0 && !point.observations.empty()) {
      reference = point.observations.begin()->first;
    }
    const auto it = corrections.find(reference);
    if (it != corrections.end()) moved.emplace_back(id, it->second.Inverse() * point.p_in_world);
  }
  for (const auto& [id, correction] : corrections) {
    const auto it = pose_index.find(id);
    if (it != pose_index.end()) {
      data.SetKeyframePose(id, snapshot.problem.poses[it->second].cam_from_world);
    } else {
      // cam_from_world_after = cam_from_world_before * world_before_from_world_after.
      data.SetKeyframePose(id, data.FindKeyframe(id)->cam_from_world * correction);
      ++result->num_corrected_keyframes;
    }
  }
  if (options.erase_outliers) {
    result->num_erased_observations = EraseOutliers(data, snapshot, result->summary.outliers);
  }
  for (std::size_t j = 0; j < snapshot.point_ids.size(); ++j) {
    const MapPoint* point = data.FindMapPoint(snapshot.point_ids[j]);
    if (point == nullptr) continue;
    if (point->observations.empty()) {
      data.EraseMapPoint(snapshot.point_ids[j]);
      continue;
    }
    data.SetMapPointPosition(snapshot.point_ids[j], snapshot.problem.points[j].p_in_world);
    data.UpdateNormalAndDepth(snapshot.point_ids[j]);
  }
  for (const auto& [id, position] : moved) {
    data.SetMapPointPosition(id, position);
    data.UpdateNormalAndDepth(id);
    ++result->num_corrected_points;
  }
}

GlobalBundleAdjustmentResult RunGlobalBundleAdjustment(
    Map& map, const GlobalBundleAdjustmentOptions& options, MarkerLandmarks* landmarks) {
  GlobalBundleAdjustmentResult result;
  if (!options.Check()) {
    result.summary.message = "invalid options";
    return result;
  }
  GlobalBundleAdjustmentSnapshot snapshot =
      map.Read([&](const MapData& data) { return TakeGlobalSnapshot(data, options, landmarks); });
  result.num_keyframes = static_cast<int>(snapshot.keyframe_ids.size());
  result.num_points = static_cast<int>(snapshot.point_ids.size());
  if (snapshot.problem.observations.empty()) {
    result.summary.message = "no observations";
    return result;
  }
  result.summary = SolveGlobalSnapshot(options, &snapshot);
  if (!result.summary.success) return result;
  map.Write([&](MapData& data) {
    ApplyGlobalBundleAdjustment(data, snapshot, options, &result, landmarks);
  });
  result.applied = true;
  return result;
}

}  // namespace arucoslam
