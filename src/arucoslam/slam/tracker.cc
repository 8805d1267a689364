#include "arucoslam/slam/tracker.h"

#include <algorithm>
#include <map>
#include <set>
#include <vector>

#include "arucoslam/feature/feature_grid.h"
#include "arucoslam/slam/projection_queries.h"

namespace arucoslam {
namespace {}  // namespace

std::string TrackingStateName(TrackingState state) {
  switch (state) {
    case TrackingState::kNotInitialized:
      return "not initialised";
    case TrackingState::kTracking:
      return "tracking";
    case TrackingState::kLost:
      return "lost";
  }
  return "unknown";
}

bool TrackerOptions::Check() const {
  return motion_search.Check() && min_motion_matches >= 0 && reference_search.Check() &&
         min_reference_matches >= 0 && covisible_per_keyframe >= 0 && max_local_keyframes >= 1 &&
         local_map_search.Check() && min_view_cos >= -1.0 && min_view_cos <= 1.0 &&
         min_pose_inliers >= 3 && min_local_map_inliers >= min_pose_inliers && pose.Check();
}

Tracker::Tracker(Map& map, const TrackerOptions& options) : map_(map), options_(options) {}

void Tracker::Start(const Frame& frame, KeyframeId reference) {
  last_frame_ = frame;
  reference_keyframe_ = reference;
  velocity_.reset();
  state_ = TrackingState::kTracking;
}

void Tracker::Reset() {
  last_frame_.reset();
  velocity_.reset();
  reference_keyframe_ = KeyframeId();
  state_ = TrackingState::kNotInitialized;
}

TrackingResult Tracker::Track(Frame& frame) {
  TrackingResult result;
  result.state = state_;
  if (state_ == TrackingState::kNotInitialized || !last_frame_) return result;
  frame.ResetMatches();
  frame.cam_from_world.reset();
  bool ok = false;
  if (velocity_ && state_ == TrackingState::kTracking) ok = TrackWithMotionModel(frame, result);
  if (!ok) {
    frame.ResetMatches();
    ok = TrackReferenceKeyframe(frame, result);
  }
  if (ok) ok = TrackLocalMap(frame, result);
  if (!ok) {
    frame.cam_from_world.reset();
    velocity_.reset();
    state_ = TrackingState::kLost;
    result.state = state_;
    result.method.clear();
    return result;
  }
  velocity_ = *frame.cam_from_world * last_frame_->cam_from_world->Inverse();
  last_frame_ = frame;
  state_ = TrackingState::kTracking;
  result.state = state_;
  return result;
}

bool Tracker::TrackWithMotionModel(Frame& frame, TrackingResult& result) {
  const Rigid3 predicted = *velocity_ * *last_frame_->cam_from_world;
  ProjectionQueries set;
  map_.Read([&](const MapData& data) {
    for (std::size_t i = 0; i < last_frame_->map_point_ids.size(); ++i) {
      const MapPoint* point = data.FindMapPoint(last_frame_->map_point_ids[i]);
      if (point == nullptr) continue;
      const std::optional<Eigen::Vector2d> pixel =
          frame.camera.Project(predicted * point->p_in_world);
      if (!pixel || !frame.camera.InImage(*pixel)) continue;
      const cv::KeyPoint& keypoint = last_frame_->features.keypoints[i];
      set.Add(point->id, *pixel, keypoint.octave, point->descriptor, 1.0, keypoint.angle);
    }
  });
  set.Finalize();
  const FeatureGrid grid(frame.features);
  std::vector<FeatureMatch> matches =
      MatchByProjection(frame.features, grid, set.queries, {}, options_.motion_search);
  if (static_cast<int>(matches.size()) < options_.min_motion_matches) {
    ProjectionMatchOptions wide = options_.motion_search;
    wide.base_radius_px *= 2.0;
    matches = MatchByProjection(frame.features, grid, set.queries, {}, wide);
  }
  result.num_initial_matches = static_cast<int>(matches.size());
  if (result.num_initial_matches < options_.min_motion_matches) return false;
  set.AssignTo(matches, frame);
  result.num_initial_inliers = OptimizeFramePose(frame, predicted);
  result.method = "motion";
  return result.num_initial_inliers >= options_.min_pose_inliers;
}

bool Tracker::TrackReferenceKeyframe(Frame& frame, TrackingResult& result) {
  std::vector<FeatureMatch> matches;
  std::vector<MapPointId> reference_points;
  map_.Read([&](const MapData& data) {
    const Keyframe* reference = data.FindKeyframe(reference_keyframe_);
    if (reference == nullptr) return;
    matches = MatchBruteForce(reference->features, frame.features, options_.reference_search);
    reference_points = reference->map_point_ids;
  });
  int count = 0;
  for (const FeatureMatch& match : matches) {
    const MapPointId point = reference_points[match.index1];
    if (!point.IsValid() || frame.map_point_ids[match.index2].IsValid()) continue;
    frame.map_point_ids[match.index2] = point;
    ++count;
  }
  result.num_initial_matches = count;
  if (count < options_.min_reference_matches) return false;
  result.num_initial_inliers = OptimizeFramePose(frame, *last_frame_->cam_from_world);
  result.method = "reference";
  return result.num_initial_inliers >= options_.min_pose_inliers;
}

int Tracker::OptimizeFramePose(Frame& frame, const Rigid3& initial) {
  std::vector<PoseObservation> observations;
  std::vector<int> keypoint_of;
  map_.Read([&](const MapData& data) {
    for (std::size_t i = 0; i < frame.map_point_ids.size(); ++i) {
      const MapPoint* point = data.FindMapPoint(frame.map_point_ids[i]);
      if (point == nullptr) {
        frame.map_point_ids[i] = MapPointId();
        continue;
      }
      const int index = static_cast<int>(i);
      observations.push_back(
          {point->p_in_world, frame.UndistortedPixel(index), frame.SigmaPx(index)});
      keypoint_of.push_back(index);
    }
  });
  PoseOptimizationOptions pose_options = options_.pose;
  pose_options.min_inliers = options_.min_pose_inliers;
  const PoseOptimizationResult optimized = OptimizePose(
      observations, initial, PinholeIntrinsics::FromCamera(frame.camera), pose_options);
  if (!optimized.success) return 0;
  frame.cam_from_world = optimized.cam_from_world;
  for (std::size_t k = 0; k < observations.size(); ++k) {
    if (!optimized.inliers[k]) frame.map_point_ids[keypoint_of[k]] = MapPointId();
  }
  return optimized.num_inliers;
}

}  // namespace arucoslam
