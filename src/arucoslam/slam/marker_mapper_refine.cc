// MarkerMapper's bundle adjustments: one new marker against its views, the mapped markers
// against the recorded poses, and the whole map with every marker view (retired ones too).
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <utility>

#include "arucoslam/markers/marker_pose.h"
#include "arucoslam/optim/marker_factors.h"
#include "arucoslam/slam/marker_mapper.h"

namespace arucoslam {

Rigid3 MarkerMapper::RefineNewMarker(const Rigid3& initial,
                                     const std::vector<const View*>& views) const {
  MarkerBundleAdjustmentProblem problem;
  problem.markers.push_back({initial, unknown_size_, false});
  for (const View* view : views) {
    const Record& record = records_.at(view->record);
    if (problem.keypoints.poses.empty()) {
      problem.keypoints.intrinsics = PinholeIntrinsics::FromCamera(record.camera);
    }
    problem.marker_observations.push_back({problem.keypoints.poses.size(), 0,
                                           UndistortedCorners(record.camera, view->corners_px),
                                           options_.corner_sigma_px});
    problem.keypoints.poses.push_back({record.cam_from_world, true});
  }
  const MarkerBundleAdjustmentSummary summary =
      SolveMarkerBundleAdjustment(options_.bundle_adjustment, &problem);
  return summary.success ? problem.markers.front().world_from_marker : initial;
}

MarkerBundleAdjustmentProblem MarkerMapper::BuildProblem(const MapData* map,
                                                         ProblemIndex* index) const {
  MarkerBundleAdjustmentProblem problem;
  auto& keypoints = problem.keypoints;
  std::map<KeyframeId, std::size_t> pose_index;
  std::map<KeyframeId, const CameraModel*> cameras;
  const auto add_pose = [&](const Rigid3& cam_from_world, const CameraModel& camera,
                            bool fixed) {
    if (keypoints.poses.empty()) keypoints.intrinsics = PinholeIntrinsics::FromCamera(camera);
    keypoints.poses.push_back({cam_from_world, fixed});
    return keypoints.poses.size() - 1;
  };
  const auto add_keyframe = [&](KeyframeId id, const Rigid3& cam_from_world,
                                const CameraModel& camera, bool fixed) {
    pose_index[id] = add_pose(cam_from_world, camera, fixed);
    cameras[id] = &camera;
    index->keyframes.push_back(id);
  };
  if (map != nullptr) {
    for (const auto& [id, keyframe] : map->keyframes()) {
      add_keyframe(id, keyframe.cam_from_world, keyframe.camera, false);
    }
    std::map<MapPointId, std::size_t> point_index;
    for (const auto& [id, point] : map->map_points()) {
      point_index[id] = keypoints.points.size();
      keypoints.points.push_back({point.p_in_world, false});
      index->points.push_back(id);
    }
    for (const auto& [id, keyframe] : map->keyframes()) {
      for (std::size_t i = 0; i < keyframe.map_point_ids.size(); ++i) {
        const auto it = point_index.find(keyframe.map_point_ids[i]);
        if (it == point_index.end()) continue;
        const int point = static_cast<int>(i);
        keypoints.observations.push_back({pose_index.at(id), it->second,
                                          keyframe.UndistortedPixel(point),
                                          keyframe.SigmaPx(point)});
      }
    }
  } else {
    for (const auto& [id, record] : live_) {
      const Record& live = records_.at(record);
      add_keyframe(id, live.cam_from_world, live.camera, true);
    }
  }
  // Retired views: with the map, a pose of its own (free) that only relative marker poses
  // constrain, so it needs two markers; without, a fixed pose like the live ones. Either
  // way one of its markers must be a mapped one (known markers do not move).
  const std::size_t min_markers = map != nullptr ? 2 : 1;
  std::map<MarkerId, std::vector<std::pair<std::size_t, const MarkerObservation*>>> retired_views;
  for (const auto& [id, record] : records_) {
    if (record.keyframe.IsValid()) continue;
    std::vector<const MarkerObservation*> seen;
    bool sees_mapped = false;
    for (const MarkerObservation& observation : record.markers) {
      const MarkerLandmark* landmark = landmarks_.Find(observation.marker_id);
      if (landmark == nullptr) continue;
      seen.push_back(&observation);
      sees_mapped = sees_mapped || !landmark->fixed;
    }
    if (seen.size() < min_markers || !sees_mapped) continue;
    const bool free_view = map != nullptr || (record.generation == kMarkerViewGeneration &&
                                              seen.size() >= 2);
    const std::size_t pose = add_pose(record.cam_from_world, record.camera, !free_view);
    index->retired.push_back(id);
    for (const MarkerObservation* observation : seen) {
      retired_views[observation->marker_id].push_back({pose, observation});
    }
  }
  std::map<std::size_t, const CameraModel*> retired_cameras;
  for (std::size_t i = 0; i < index->retired.size(); ++i) {
    retired_cameras[index->keyframes.size() + i] = &records_.at(index->retired[i]).camera;
  }
  bool fixed_marker_seen = false;
  for (const auto& [id, landmark] : landmarks_.landmarks()) {
    const std::size_t marker_index = problem.markers.size();
    const std::size_t first_observation = problem.marker_observations.size();
    for (const auto& [keyframe, corners_px] : landmark.observations) {
      const auto it = pose_index.find(keyframe);
      if (it == pose_index.end()) continue;
      problem.marker_observations.push_back({it->second, marker_index,
                                             UndistortedCorners(*cameras.at(keyframe), corners_px),
                                             options_.corner_sigma_px});
    }
    const auto retired = retired_views.find(id);
    if (retired != retired_views.end()) {
      for (const auto& [pose, observation] : retired->second) {
        problem.marker_observations.push_back(
            {pose, marker_index,
             UndistortedCorners(*retired_cameras.at(pose), observation->corners_px),
             options_.corner_sigma_px});
      }
    }
    if (problem.marker_observations.size() == first_observation) continue;  // not seen
    problem.markers.push_back({landmark.world_from_marker, landmark.size, landmark.fixed});
    index->markers.push_back(id);
    fixed_marker_seen = fixed_marker_seen || landmark.fixed;
  }
  // Without a known marker the gauge (and the monocular scale) rests on the first keyframe.
  if (!fixed_marker_seen && !keypoints.poses.empty()) keypoints.poses.front().fixed = true;
  return problem;
}

MarkerBundleAdjustmentSummary MarkerMapper::Refine(MapData* map) {
  ProblemIndex index;
  MarkerBundleAdjustmentProblem problem = BuildProblem(map, &index);
  problem.ground_plane_prior = options_.ground_plane_prior;
  problem.position_priors = PositionPriorsOf(position_priors_, index.keyframes);
  MarkerBundleAdjustmentSummary summary =
      SolveMarkerBundleAdjustment(options_.bundle_adjustment, &problem);
  if (!summary.success) return summary;
  if (options_.balance_corner_sigma) {
    const std::optional<double> sigma_px = BalancedCornerSigmaPx(
        problem, options_.min_corner_sigma_px, options_.max_corner_sigma_px);
    if (sigma_px && std::abs(*sigma_px / options_.corner_sigma_px - 1.0) > 0.2) {
      for (auto& observation : problem.marker_observations) observation.sigma_px = *sigma_px;
      const MarkerBundleAdjustmentSummary second =
          SolveMarkerBundleAdjustment(options_.bundle_adjustment, &problem);
      if (!second.success) return second;
      summary = second;
      summary.corner_sigma_px = *sigma_px;
    }
  }
  for (std::size_t i = 0; i < index.keyframes.size(); ++i) {
    const Rigid3& cam_from_world = problem.keypoints.poses[i].cam_from_world;
    map->SetKeyframePose(index.keyframes[i], cam_from_world);
    const auto live = live_.find(index.keyframes[i]);
    if (live != live_.end()) records_.at(live->second).cam_from_world = cam_from_world;
  }
  for (std::size_t i = 0; i < index.retired.size(); ++i) {
    records_.at(index.retired[i]).cam_from_world =
        problem.keypoints.poses[index.keyframes.size() + i].cam_from_world;
  }
  for (std::size_t i = 0; i < index.points.size(); ++i) {
    map->SetMapPointPosition(index.points[i], problem.keypoints.points[i].p_in_world);
    map->UpdateNormalAndDepth(index.points[i]);
  }
  for (std::size_t i = 0; i < index.markers.size(); ++i) {
    landmarks_.SetPose(index.markers[i], problem.markers[i].world_from_marker);  // no-op if fixed
  }
  return summary;
}

int MarkerMapper::ReconsiderMappedMarkers() {
  constexpr double kCapPx = 5.0;        // a view's RMS counts at most this much
  constexpr int kMaxCandidateViews = 12;  // views whose IPPE solutions are tried
  struct SeenBy {
    const Record* record;
    const MarkerObservation* observation;
  };
  int moved = 0;
  for (const auto& [id, landmark] : landmarks_.landmarks()) {
    if (landmark.fixed) continue;
    std::vector<SeenBy> views;
    for (const auto& [index, record] : records_) {
      for (const MarkerObservation& observation : record.markers) {
        if (observation.marker_id == id) views.push_back({&record, &observation});
      }
    }
    if (views.size() < 2) continue;
    const std::array<Eigen::Vector3d, 4> corners = SquareCorners(landmark.size);
    const auto error = [&](const Rigid3& world_from_marker) {
      double sum = 0.0;
      for (const SeenBy& view : views) {
        const double rms = MarkerReprojectionRms(
            view.record->camera, view.record->cam_from_world * world_from_marker, corners,
            view.observation->corners_px);
        sum += std::min(rms * rms, kCapPx * kCapPx);
      }
      return sum;
    };
    const double current = error(landmark.world_from_marker);
    double best_error = current;
    std::optional<Rigid3> best;
    const std::size_t step = std::max<std::size_t>(1, views.size() / kMaxCandidateViews);
    for (std::size_t v = 0; v < views.size(); v += step) {
      const std::optional<MarkerPose> pose =
          EstimateMarkerPose(views[v].observation->AsDetection(), landmark.size,
                             views[v].record->camera, options_.marker_pose);
      if (!pose) continue;
      const Rigid3 world_from_cam = views[v].record->cam_from_world.Inverse();
      for (int s = 0; s < pose->num_solutions; ++s) {
        const Rigid3 candidate = world_from_cam * pose->solutions[s].cam_from_marker;
        const double candidate_error = error(candidate);
        if (candidate_error < best_error) {
          best_error = candidate_error;
          best = candidate;
        }
      }
    }
    if (best && best_error < 0.5 * current) {
      landmarks_.SetPose(id, *best);
      ++moved;
    }
  }
  return moved;
}

MarkerBundleAdjustmentSummary MarkerMapper::RefineMarkers() {
  ReconsiderMappedMarkers();
  ProblemIndex index;
  MarkerBundleAdjustmentProblem problem = BuildProblem(nullptr, &index);
  const MarkerBundleAdjustmentSummary summary =
      SolveMarkerBundleAdjustment(options_.bundle_adjustment, &problem);
  if (!summary.success) return summary;
  for (std::size_t i = 0; i < index.retired.size(); ++i) {
    records_.at(index.retired[i]).cam_from_world =
        problem.keypoints.poses[index.keyframes.size() + i].cam_from_world;  // fixed or view
  }
  for (std::size_t i = 0; i < index.markers.size(); ++i) {
    landmarks_.SetPose(index.markers[i], problem.markers[i].world_from_marker);
  }
  return summary;
}

}  // namespace arucoslam
