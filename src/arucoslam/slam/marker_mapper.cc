#include "arucoslam/slam/marker_mapper.h"

#include <algorithm>
#include <limits>

namespace arucoslam {

MarkerMapper::MarkerMapper(const MarkerMap& known, const MarkerMapperOptions& options)
    : options_(options),
      dictionary_(known.dictionary),
      unknown_size_(options.unknown_marker_size_m),
      landmarks_(MarkerLandmarks::FromMarkerMap(known)) {
  if (!(unknown_size_ > 0.0) && !known.markers.empty()) {
    unknown_size_ = known.markers.begin()->second.size;
  }
  if (!options.map_unknown) unknown_size_ = 0.0;
}

std::vector<MarkerId> MarkerMapper::AddKeyframe(KeyframeId keyframe, const Rigid3& cam_from_world,
                                                const CameraModel& camera,
                                                const std::vector<MarkerObservation>& markers) {
  keyframes_[keyframe] = {cam_from_world, camera};
  std::vector<MarkerId> initialised;
  for (const MarkerObservation& observation : markers) {
    if (landmarks_.Contains(observation.marker_id)) {
      landmarks_.AddObservation(observation.marker_id, keyframe, observation.corners_px);
    } else if (unknown_size_ > 0.0) {
      Observe(keyframe, observation, &initialised);
    }
  }
  return initialised;
}

void MarkerMapper::EraseKeyframe(KeyframeId keyframe) {
  keyframes_.erase(keyframe);
  landmarks_.EraseKeyframe(keyframe);
  for (auto& [id, views] : pending_) {
    std::erase_if(views, [&](const View& view) { return view.keyframe == keyframe; });
  }
  std::erase_if(pending_, [](const auto& entry) { return entry.second.empty(); });
}

void MarkerMapper::SyncKeyframes(const MapData& map) {
  std::vector<KeyframeId> gone;
  for (auto& [id, record] : keyframes_) {
    const Keyframe* keyframe = map.FindKeyframe(id);
    if (keyframe == nullptr) {
      gone.push_back(id);
    } else {
      record.cam_from_world = keyframe->cam_from_world;
    }
  }
  for (const KeyframeId& id : gone) EraseKeyframe(id);
}

void MarkerMapper::Observe(KeyframeId keyframe, const MarkerObservation& observation,
                           std::vector<MarkerId>* initialised) {
  MarkerDetection detection;
  detection.id = observation.marker_id.value;
  detection.corners = observation.corners_px;
  const std::optional<MarkerPose> pose = EstimateMarkerPose(
      detection, unknown_size_, keyframes_.at(keyframe).camera, options_.marker_pose);
  if (!pose || pose->Best().reprojection_rms_px > options_.max_initial_rms_px) return;
  std::vector<View>& views = pending_[observation.marker_id];
  std::erase_if(views, [&](const View& view) { return view.keyframe == keyframe; });
  views.push_back({keyframe, observation.corners_px, *pose});
  if (TryInitialise(observation.marker_id)) initialised->push_back(observation.marker_id);
}

double MarkerMapper::ViewsSquaredError(const std::vector<View>& views,
                                       const Rigid3& world_from_marker) const {
  const std::array<Eigen::Vector3d, 4> corners = SquareCorners(unknown_size_);
  double sum = 0.0;
  for (const View& view : views) {
    const KeyframeRecord& record = keyframes_.at(view.keyframe);
    const double rms = MarkerReprojectionRms(
        record.camera, record.cam_from_world * world_from_marker, corners, view.corners_px);
    sum += rms * rms;
  }
  return sum;
}

bool MarkerMapper::TryInitialise(MarkerId id) {
  const std::vector<View>& views = pending_.at(id);
  bool any_unambiguous = false;
  for (const View& view : views) any_unambiguous = any_unambiguous || !view.pose.ambiguous;
  if (!any_unambiguous && static_cast<int>(views.size()) < options_.views_to_resolve_ambiguity) {
    return false;
  }
  // Every IPPE solution of every view is a candidate; the one that explains all views best
  // wins (an unambiguous view's best solution, or the one a second view agrees with).
  double best_error = std::numeric_limits<double>::infinity();
  Rigid3 best;
  for (const View& view : views) {
    const Rigid3 world_from_cam = keyframes_.at(view.keyframe).cam_from_world.Inverse();
    for (int s = 0; s < view.pose.num_solutions; ++s) {
      const Rigid3 candidate = world_from_cam * view.pose.solutions[s].cam_from_marker;
      const double error = ViewsSquaredError(views, candidate);
      if (error < best_error) {
        best_error = error;
        best = candidate;
      }
    }
  }
  MarkerLandmark landmark;
  landmark.id = id;
  landmark.size = unknown_size_;
  landmark.world_from_marker = best;
  landmark.fixed = false;
  for (const View& view : views) landmark.observations[view.keyframe] = view.corners_px;
  landmarks_.Add(std::move(landmark));
  pending_.erase(id);
  return true;
}

MarkerBundleAdjustmentProblem MarkerMapper::BuildProblem(const MapData* map,
                                                         std::vector<KeyframeId>* poses,
                                                         std::vector<MapPointId>* points,
                                                         std::vector<MarkerId>* markers) const {
  MarkerBundleAdjustmentProblem problem;
  auto& keypoints = problem.keypoints;
  std::map<KeyframeId, std::size_t> pose_index;
  std::map<KeyframeId, const CameraModel*> cameras;
  const auto add_pose = [&](KeyframeId id, const Rigid3& cam_from_world, const CameraModel& camera,
                            bool fixed) {
    if (keypoints.poses.empty()) keypoints.intrinsics = PinholeIntrinsics::FromCamera(camera);
    pose_index[id] = keypoints.poses.size();
    cameras[id] = &camera;
    keypoints.poses.push_back({cam_from_world, fixed});
    poses->push_back(id);
  };
  if (map != nullptr) {
    for (const auto& [id, keyframe] : map->keyframes()) {
      add_pose(id, keyframe.cam_from_world, keyframe.camera, false);
    }
    std::map<MapPointId, std::size_t> point_index;
    for (const auto& [id, point] : map->map_points()) {
      point_index[id] = keypoints.points.size();
      keypoints.points.push_back({point.p_in_world, false});
      points->push_back(id);
    }
    for (const auto& [id, keyframe] : map->keyframes()) {
      for (std::size_t i = 0; i < keyframe.map_point_ids.size(); ++i) {
        const auto it = point_index.find(keyframe.map_point_ids[i]);
        if (it == point_index.end()) continue;
        const int index = static_cast<int>(i);
        keypoints.observations.push_back({pose_index.at(id), it->second,
                                          keyframe.UndistortedPixel(index),
                                          keyframe.SigmaPx(index)});
      }
    }
  } else {
    for (const auto& [id, record] : keyframes_) {
      add_pose(id, record.cam_from_world, record.camera, true);
    }
  }
  bool fixed_marker_seen = false;
  for (const auto& [id, landmark] : landmarks_.landmarks()) {
    const std::size_t marker_index = problem.markers.size();
    for (const auto& [keyframe, corners_px] : landmark.observations) {
      const auto it = pose_index.find(keyframe);
      if (it == pose_index.end()) continue;
      problem.marker_observations.push_back({it->second, marker_index,
                                             UndistortedCorners(*cameras.at(keyframe), corners_px),
                                             options_.corner_sigma_px});
    }
    if (problem.marker_observations.empty() ||
        problem.marker_observations.back().marker_index != marker_index) {
      continue;  // not seen by any keyframe of the problem
    }
    problem.markers.push_back({landmark.world_from_marker, landmark.size, landmark.fixed});
    markers->push_back(id);
    fixed_marker_seen = fixed_marker_seen || landmark.fixed;
  }
  // Without a known marker the gauge (and the monocular scale) rests on the first keyframe.
  if (!fixed_marker_seen && !keypoints.poses.empty()) keypoints.poses.front().fixed = true;
  return problem;
}

MarkerBundleAdjustmentSummary MarkerMapper::Refine(MapData* map) {
  std::vector<KeyframeId> poses;
  std::vector<MapPointId> points;
  std::vector<MarkerId> markers;
  MarkerBundleAdjustmentProblem problem = BuildProblem(map, &poses, &points, &markers);
  const MarkerBundleAdjustmentSummary summary =
      SolveMarkerBundleAdjustment(options_.bundle_adjustment, &problem);
  if (!summary.success) return summary;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Rigid3& cam_from_world = problem.keypoints.poses[i].cam_from_world;
    map->SetKeyframePose(poses[i], cam_from_world);
    const auto record = keyframes_.find(poses[i]);
    if (record != keyframes_.end()) record->second.cam_from_world = cam_from_world;
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    map->SetMapPointPosition(points[i], problem.keypoints.points[i].p_in_world);
    map->UpdateNormalAndDepth(points[i]);
  }
  for (std::size_t i = 0; i < markers.size(); ++i) {
    landmarks_.SetPose(markers[i], problem.markers[i].world_from_marker);  // no-op when fixed
  }
  return summary;
}

MarkerBundleAdjustmentSummary MarkerMapper::RefineMarkers() {
  std::vector<KeyframeId> poses;
  std::vector<MapPointId> points;
  std::vector<MarkerId> markers;
  MarkerBundleAdjustmentProblem problem = BuildProblem(nullptr, &poses, &points, &markers);
  const MarkerBundleAdjustmentSummary summary =
      SolveMarkerBundleAdjustment(options_.bundle_adjustment, &problem);
  if (!summary.success) return summary;
  for (std::size_t i = 0; i < markers.size(); ++i) {
    landmarks_.SetPose(markers[i], problem.markers[i].world_from_marker);
  }
  return summary;
}

MarkerMap MarkerMapper::ToMarkerMap() const { return landmarks_.ToMarkerMap(dictionary_); }

}  // namespace arucoslam
