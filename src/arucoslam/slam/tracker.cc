#include "arucoslam/slam/tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <vector>

#include "arucoslam/feature/feature_grid.h"
#include "arucoslam/slam/projection_queries.h"
#include "arucoslam/util/logging.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

void LogResult(const Frame& frame, const TrackingResult& result) {
  ARUCOSLAM_LOG_DEBUG("frame {}: {} {} matches {} inliers, +{} local, {} final -> {}",
                      frame.id.value, result.method.empty() ? "-" : result.method,
                      result.num_initial_matches, result.num_initial_inliers,
                      result.num_local_map_matches, result.num_inliers,
                      TrackingStateName(result.state));
}

}  // namespace

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

bool TrackerOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Nested("motion_search", motion_search);
  check.AtLeast("min_motion_matches", min_motion_matches, 0);
  check.Nested("reference_search", reference_search);
  check.AtLeast("min_reference_matches", min_reference_matches, 0);
  check.AtLeast("covisible_per_keyframe", covisible_per_keyframe, 0);
  check.AtLeast("max_local_keyframes", max_local_keyframes, 1);
  check.Nested("local_map_search", local_map_search);
  check.InRange("min_view_cos", min_view_cos, -1.0, 1.0, Interval::kClosed);
  check.AtLeast("recovery_frames", recovery_frames, 0);
  check.AtLeast("max_prediction_gap_s", max_prediction_gap_s, 0.0);
  check.AtLeast("min_pose_inliers", min_pose_inliers, 3);
  check.AtLeast("min_local_map_inliers", min_local_map_inliers, min_pose_inliers,
                "min_pose_inliers");
  check.AtLeast("min_weak_inliers", min_weak_inliers, min_pose_inliers, "min_pose_inliers");
  check.AtMost("min_weak_inliers", min_weak_inliers, min_local_map_inliers,
               "min_local_map_inliers");
  check.AtLeast("weak_max_rotation_deg", weak_max_rotation_deg, 0.0);
  check.AtLeast("weak_max_center_steps", weak_max_center_steps, 0.0);
  check.AtLeast("weak_radius_factor", weak_radius_factor, 1.0);
  check.Nested("pose", pose);
  check.Nested("marker_pose", marker_pose);
  check.InRange("relocalization_min_axis_cos", relocalization_min_axis_cos, -1.0, 1.0,
                Interval::kClosed);
  return check.ok();
}

Tracker::Tracker(Map& map, const TrackerOptions& options) : map_(map), options_(options) {
}

void Tracker::Start(const Frame& frame, KeyframeId reference) {
  last_frame_ = frame;
  reference_keyframe_ = reference;
  velocity_.reset();
  frames_lost_ = 0;
  frame_period_s_ = 0.0;
  state_ = TrackingState::kTracking;
}

void Tracker::Reset() {
  last_frame_.reset();
  velocity_.reset();
  frames_lost_ = 0;
  frame_period_s_ = 0.0;
  reference_keyframe_ = KeyframeId();
  state_ = TrackingState::kNotInitialized;
}

TrackingResult Tracker::Track(Frame& frame, const std::vector<MarkerPoseObservation>& markers) {
  markers_ = &markers;
  struct Clear {
    const std::vector<MarkerPoseObservation>** markers;
    ~Clear() { *markers = nullptr; }
  } clear{&markers_};
  TrackingResult result;
  result.state = state_;
  if (state_ == TrackingState::kNotInitialized || !last_frame_) return result;
  frame.ResetMatches();
  frame.cam_from_world.reset();
  const std::optional<int> motion_steps = MotionSteps(frame.timestamp_s);
  const bool use_motion = motion_steps.has_value();
  const int steps = motion_steps.value_or(frames_lost_ + 1);
  bool ok = false;
  if (use_motion) ok = TrackWithMotionModel(frame, result, steps);
  if (!ok) {
    frame.ResetMatches();
    ok = TrackReferenceKeyframe(frame, result);
  }
  if (ok) ok = TrackLocalMap(frame, result);
  if (!ok && use_motion) {
    frame.ResetMatches();
    ok = TrackFromPrediction(frame, result, steps);
  }
  if (!ok) {
    frame.cam_from_world.reset();
    if (++frames_lost_ > options_.recovery_frames) velocity_.reset();
    state_ = TrackingState::kLost;
    result.state = state_;
    LogResult(frame, result);
    result.method.clear();
    return result;
  }
  velocity_ = *frame.cam_from_world * last_frame_->cam_from_world->Inverse();
  if (steps > 1) velocity_ = Rigid3::Exp(velocity_->Log() / steps);
  const double elapsed_s = frame.timestamp_s - last_frame_->timestamp_s;
  frame_period_s_ = elapsed_s > 0.0 ? elapsed_s / steps : 0.0;
  frames_lost_ = 0;
  last_frame_ = frame;
  state_ = TrackingState::kTracking;
  result.state = state_;
  LogResult(frame, result);
  return result;
}

std::optional<int> Tracker::MotionSteps(double timestamp_s) const {
  if (!velocity_ || !last_frame_) return std::nullopt;
  const int steps = frames_lost_ + 1;
  if (!(frame_period_s_ > 0.0)) return steps;
  const double elapsed_s = timestamp_s - last_frame_->timestamp_s;
  if (elapsed_s > options_.max_prediction_gap_s) return std::nullopt;
  return std::max(steps, static_cast<int>(std::lround(elapsed_s / frame_period_s_)));
}

Rigid3 Tracker::Predict(int steps) const {
  Rigid3 predicted = *last_frame_->cam_from_world;
  for (int k = 0; k < steps; ++k) predicted = *velocity_ * predicted;
  return predicted;
}

bool Tracker::AgreesWithPrediction(const Rigid3& cam_from_world, int steps) const {
  if (!velocity_) return false;
  const Rigid3 predicted = Predict(steps);
  const double rotation_deg =
      predicted.rotation.angularDistance(cam_from_world.rotation) * 180.0 / M_PI;
  const double center_error =
      (predicted.Inverse().translation - cam_from_world.Inverse().translation).norm();
  const double step_length = velocity_->translation.norm();
  return rotation_deg <= options_.weak_max_rotation_deg * steps &&
         center_error <= options_.weak_max_center_steps * step_length * steps;
}

bool Tracker::TrackFromPrediction(Frame& frame, TrackingResult& result, int steps) {
  frame.cam_from_world = Predict(steps);
  result = TrackingResult{state_, "prediction", 0, 0, 0, 0};
  // Recovering: the prediction is older, the window twice as wide (as in the motion model).
  return TrackLocalMap(frame, result, options_.weak_radius_factor * (steps > 1 ? 2.0 : 1.0));
}

bool Tracker::TrackWithMotionModel(Frame& frame, TrackingResult& result, int steps) {
  const Rigid3 predicted = Predict(steps);
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
  ProjectionMatchOptions search = options_.motion_search;
  if (steps > 1) search.base_radius_px *= 2.0;  // recovering: the prediction is older
  std::vector<FeatureMatch> matches =
      MatchByProjection(frame.features, grid, set.queries, {}, search);
  if (static_cast<int>(matches.size()) < options_.min_motion_matches) {
    search.base_radius_px *= 2.0;
    matches = MatchByProjection(frame.features, grid, set.queries, {}, search);
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

void Tracker::MarkLost() {
  state_ = TrackingState::kLost;
  velocity_.reset();
  frames_lost_ = options_.recovery_frames + 1;
}

TrackingResult Tracker::TrackFromPose(Frame& frame, const Rigid3& cam_from_world,
                                      const std::vector<MarkerPoseObservation>& markers) {
  markers_ = &markers;
  struct Clear {
    const std::vector<MarkerPoseObservation>** markers;
    ~Clear() { *markers = nullptr; }
  } clear{&markers_};
  TrackingResult result;
  result.state = state_;
  const KeyframeId nearest = NearestKeyframe(cam_from_world);
  if (!nearest.IsValid()) return result;
  frame.ResetMatches();
  ProjectionQueries set;
  map_.Read([&](const MapData& data) {
    const Keyframe& keyframe = *data.FindKeyframe(nearest);
    for (std::size_t i = 0; i < keyframe.map_point_ids.size(); ++i) {
      const MapPoint* point = data.FindMapPoint(keyframe.map_point_ids[i]);
      if (point == nullptr) continue;
      const std::optional<Eigen::Vector2d> pixel =
          frame.camera.Project(cam_from_world * point->p_in_world);
      if (!pixel || !frame.camera.InImage(*pixel)) continue;
      const cv::KeyPoint& keypoint = keyframe.features.keypoints[i];
      set.Add(point->id, *pixel, keypoint.octave, point->descriptor, 1.0, keypoint.angle);
    }
  });
  set.Finalize();
  ProjectionMatchOptions wide = options_.motion_search;
  wide.base_radius_px *= 2.0;
  const std::vector<FeatureMatch> matches =
      MatchByProjection(frame.features, FeatureGrid(frame.features), set.queries, {}, wide);
  result.num_initial_matches = static_cast<int>(matches.size());
  frame.cam_from_world.reset();
  if (result.num_initial_matches < options_.min_motion_matches) return result;
  set.AssignTo(matches, frame);
  result.num_initial_inliers = OptimizeFramePose(frame, cam_from_world);
  result.method = "pose";
  if (result.num_initial_inliers < options_.min_pose_inliers ||
      !TrackLocalMap(frame, result, 1.0, /*allow_weak=*/false)) {
    frame.cam_from_world.reset();
    frame.ResetMatches();
    result.method.clear();
    return result;
  }
  last_frame_ = frame;
  velocity_.reset();
  frames_lost_ = 0;
  frame_period_s_ = 0.0;
  state_ = TrackingState::kTracking;
  result.state = state_;
  return result;
}

KeyframeId Tracker::NearestKeyframe(const Rigid3& cam_from_world) const {
  const Rigid3 world_from_cam = cam_from_world.Inverse();
  const Eigen::Vector3d axis = world_from_cam.rotation * Eigen::Vector3d::UnitZ();
  return map_.Read([&](const MapData& data) {
    KeyframeId best;
    double best_distance = std::numeric_limits<double>::infinity();
    for (const auto& [id, keyframe] : data.keyframes()) {
      const Rigid3 world_from_keyframe = keyframe.cam_from_world.Inverse();
      const Eigen::Vector3d keyframe_axis =
          world_from_keyframe.rotation * Eigen::Vector3d::UnitZ();
      if (axis.dot(keyframe_axis) < options_.relocalization_min_axis_cos) continue;
      const double distance =
          (world_from_keyframe.translation - world_from_cam.translation).norm();
      if (distance < best_distance) {
        best_distance = distance;
        best = id;
      }
    }
    return best;
  });
}

void Tracker::ApplySimilarity(const Sim3& world_from_map) {
  if (last_frame_ && last_frame_->cam_from_world) {
    last_frame_->cam_from_world =
        world_from_map.TransformPose(last_frame_->cam_from_world->Inverse()).Inverse();
  }
  if (velocity_) velocity_->translation *= world_from_map.scale;
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
  const PinholeIntrinsics intrinsics = PinholeIntrinsics::FromCamera(frame.camera);
  PoseOptimizationResult optimized;
  if (markers_ != nullptr && !markers_->empty()) {
    MarkerPoseOptimizationOptions marker_options = options_.marker_pose;
    marker_options.keypoints = pose_options;
    const MarkerPoseOptimizationResult fused =
        OptimizePoseWithMarkers(observations, *markers_, initial, intrinsics, marker_options);
    optimized.success = fused.success;
    optimized.cam_from_world = fused.cam_from_world;
    optimized.inliers = fused.inliers;
    optimized.num_inliers = fused.num_inliers;
  } else {
    optimized = OptimizePose(observations, initial, intrinsics, pose_options);
  }
  if (!optimized.success) return 0;
  frame.cam_from_world = optimized.cam_from_world;
  for (std::size_t k = 0; k < observations.size(); ++k) {
    if (!optimized.inliers[k]) frame.map_point_ids[keypoint_of[k]] = MapPointId();
  }
  return optimized.num_inliers;
}

}  // namespace arucoslam
