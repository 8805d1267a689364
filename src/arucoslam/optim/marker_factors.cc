#include "arucoslam/optim/marker_factors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include "arucoslam/geometry/pose_information.h"
#include "arucoslam/markers/marker_pose.h"
#include "arucoslam/optim/marker_corner_error.h"
#include "arucoslam/optim/marker_location_information.h"
#include "arucoslam/optim/marker_pose_optimizer.h"

namespace arucoslam {

MarkerFactors CollectMarkerFactors(const MapData& data, const std::vector<KeyframeId>& keyframe_ids,
                                   const MarkerLandmarks& landmarks,
                                   const MarkerFactorOptions& options) {
  std::map<KeyframeId, std::size_t> pose_index;
  for (std::size_t i = 0; i < keyframe_ids.size(); ++i) pose_index[keyframe_ids[i]] = i;
  MarkerFactors factors;
  for (const auto& [id, landmark] : landmarks.landmarks()) {
    const std::size_t marker_index = factors.markers.size();
    bool seen = false;
    for (const auto& [keyframe_id, corners_px] : landmark.observations) {
      const auto it = pose_index.find(keyframe_id);
      if (it == pose_index.end()) continue;
      const Keyframe* keyframe = data.FindKeyframe(keyframe_id);
      if (keyframe == nullptr) continue;
      factors.observations.push_back({it->second, marker_index,
                                      UndistortedCorners(keyframe->camera, corners_px),
                                      options.corner_sigma_px});
      seen = true;
    }
    if (!seen) continue;
    factors.markers.push_back({landmark.world_from_marker, landmark.size, landmark.fixed});
    factors.marker_ids.push_back(id);
    if (landmark.fixed) ++factors.num_fixed_markers;
  }
  return factors;
}

BundleAdjustmentSummary SolveBundleAdjustmentWithMarkers(const BundleAdjustmentOptions& solver,
                                                         const MarkerFactorOptions& options,
                                                         MarkerFactors* factors,
                                                         BundleAdjustmentProblem* problem,
                                                         std::vector<bool>* marker_outliers) {
  if (factors->empty()) {
    if (marker_outliers != nullptr) marker_outliers->clear();
    return SolveBundleAdjustment(solver, problem);
  }
  MarkerBundleAdjustmentProblem joint;
  joint.keypoints = std::move(*problem);
  joint.markers = std::move(factors->markers);
  joint.marker_observations = std::move(factors->observations);
  joint.position_priors = std::move(factors->position_priors);
  MarkerBundleAdjustmentOptions joint_options;
  joint_options.solver = solver;
  joint_options.marker_huber_delta = options.marker_huber_delta;
  joint_options.marker_chi_square_threshold = options.marker_chi_square_threshold;
  const MarkerBundleAdjustmentSummary joint_summary =
      SolveMarkerBundleAdjustment(joint_options, &joint);
  *problem = std::move(joint.keypoints);
  factors->markers = std::move(joint.markers);
  factors->observations = std::move(joint.marker_observations);
  factors->position_priors = std::move(joint.position_priors);
  if (marker_outliers != nullptr) *marker_outliers = joint_summary.marker_outliers;

  BundleAdjustmentSummary summary;
  summary.success = joint_summary.success;
  summary.num_iterations = joint_summary.num_iterations;
  summary.num_residual_blocks = joint_summary.num_residual_blocks;
  summary.initial_cost = joint_summary.initial_cost;
  summary.final_cost = joint_summary.final_cost;
  summary.initial_rms_px = joint_summary.initial_keypoint_rms_px;
  summary.final_rms_px = joint_summary.final_keypoint_rms_px;
  summary.solve_seconds = joint_summary.solve_seconds;
  summary.outliers = joint_summary.keypoint_outliers;
  summary.num_outliers = joint_summary.num_keypoint_outliers;
  summary.stopped_early = joint_summary.stopped_early;
  summary.message = joint_summary.message;
  return summary;
}

std::vector<PositionPrior> PositionPriorsOf(const std::vector<KeyframePosePrior>& priors,
                                            const std::vector<KeyframeId>& keyframe_ids) {
  std::vector<PositionPrior> out;
  for (const KeyframePosePrior& prior : priors) {
    const auto it = std::find(keyframe_ids.begin(), keyframe_ids.end(), prior.keyframe);
    if (it == keyframe_ids.end() || !(prior.information(0, 0) > 0.0)) continue;
    out.push_back({static_cast<std::size_t>(it - keyframe_ids.begin()),
                   prior.world_from_cam.translation, LeastCertainPositionSigma(prior.information)});
  }
  return out;
}

int ApplyMarkerFactors(const MarkerFactors& factors, MarkerLandmarks* landmarks) {
  int moved = 0;
  for (std::size_t i = 0; i < factors.markers.size(); ++i) {
    if (factors.markers[i].fixed) continue;
    moved += landmarks->SetPose(factors.marker_ids[i], factors.markers[i].world_from_marker) ? 1 : 0;
  }
  return moved;
}

Matrix6d MarkerPriorInformation(const MarkerFactorOptions& options, double num_markers,
                                const Matrix6d& corner_information) {
  const double position_sigma_squared =
      options.prior_position_sigma_m * options.prior_position_sigma_m;
  const double rotation_sigma_squared =
      options.prior_rotation_sigma_rad * options.prior_rotation_sigma_rad;
  if (!options.prior_from_corners) {
    Matrix6d information = Matrix6d::Zero();
    information.diagonal() << Eigen::Vector3d::Constant(num_markers / position_sigma_squared),
        Eigen::Vector3d::Constant(num_markers / rotation_sigma_squared);
    return information;
  }
  const double position_variance = position_sigma_squared / num_markers;
  const double rotation_variance = rotation_sigma_squared / num_markers;
  Eigen::Matrix<double, 6, 1> floor;
  floor << Eigen::Vector3d::Constant(position_variance),
      Eigen::Vector3d::Constant(rotation_variance);
  return WithCovarianceFloor(corner_information, floor);
}

std::vector<PoseGraphProblem::PosePrior> MarkerPosePriors(const MapData& data,
                                                          const std::vector<KeyframeId>& keyframe_ids,
                                                          const MarkerLandmarks& landmarks,
                                                          const MarkerFactorOptions& options) {
  std::map<KeyframeId, std::vector<MarkerPoseObservation>> seen;
  std::map<KeyframeId, std::vector<Rigid3>> starts;  // per keyframe: IPPE cam_from_world
  for (const auto& [id, landmark] : landmarks.landmarks()) {
    if (!landmark.fixed) continue;
    for (const auto& [keyframe_id, corners_px] : landmark.observations) {
      const Keyframe* keyframe = data.FindKeyframe(keyframe_id);
      if (keyframe == nullptr) continue;
      seen[keyframe_id].push_back({landmark.world_from_marker, landmark.size,
                                   UndistortedCorners(keyframe->camera, corners_px),
                                   options.corner_sigma_px});
      MarkerDetection detection;
      detection.id = id.value;
      detection.corners = corners_px;
      const std::optional<MarkerPose> pose =
          EstimateMarkerPose(detection, landmark.size, keyframe->camera);
      if (pose) {
        starts[keyframe_id].push_back(pose->Best().cam_from_marker *
                                      landmark.world_from_marker.Inverse());
      }
    }
  }
  MarkerPoseOptimizationOptions pose_options;
  pose_options.marker_huber_delta = options.marker_huber_delta;
  pose_options.marker_chi_square_threshold = options.marker_chi_square_threshold;
  std::vector<PoseGraphProblem::PosePrior> priors;
  for (std::size_t node = 0; node < keyframe_ids.size(); ++node) {
    const auto it = seen.find(keyframe_ids[node]);
    if (it == seen.end() || static_cast<int>(it->second.size()) < options.min_prior_markers) {
      continue;
    }
    // From the keyframe's pose (which may have drifted) and from each marker's IPPE pose;
    // the start whose result has the most inlier markers, then the smallest error, wins.
    const Keyframe* keyframe = data.FindKeyframe(keyframe_ids[node]);
    std::vector<Rigid3> initial = {keyframe->cam_from_world};
    for (const Rigid3& start : starts[keyframe_ids[node]]) initial.push_back(start);
    std::optional<MarkerPoseOptimizationResult> best;
    for (const Rigid3& start : initial) {
      MarkerPoseOptimizationResult result = OptimizePoseWithMarkers(
          {}, it->second, start, PinholeIntrinsics::FromCamera(keyframe->camera), pose_options);
      if (!result.success) continue;
      if (!best || result.num_marker_inliers > best->num_marker_inliers ||
          (result.num_marker_inliers == best->num_marker_inliers &&
           result.final_marker_rms_px < best->final_marker_rms_px)) {
        best = std::move(result);
      }
    }
    if (!best || best->num_marker_inliers < options.min_prior_markers) continue;
    const MarkerPoseOptimizationResult& result = *best;
    const Eigen::Vector3d centre = result.cam_from_world.Inverse().translation;
    double nearest_sides = std::numeric_limits<double>::infinity();
    for (const MarkerPoseObservation& marker : it->second) {
      nearest_sides = std::min(
          nearest_sides, (marker.world_from_marker.translation - centre).norm() / marker.size);
    }
    if (options.max_prior_distance_sides > 0.0 && nearest_sides > options.max_prior_distance_sides) {
      continue;
    }
    PoseGraphProblem::PosePrior prior;
    prior.node = node;
    prior.world_from_cam = result.cam_from_world.Inverse();
    Matrix6d corner_information = Matrix6d::Zero();
    if (options.prior_from_corners) {
      std::vector<MarkerPoseObservation> inliers;
      for (std::size_t i = 0; i < it->second.size(); ++i) {
        if (result.marker_inliers[i]) inliers.push_back(it->second[i]);
      }
      corner_information = MarkerLocationInformation(
          prior.world_from_cam, inliers, PinholeIntrinsics::FromCamera(keyframe->camera));
    }
    prior.information =
        MarkerPriorInformation(options, result.num_marker_inliers, corner_information);
    priors.push_back(prior);
  }
  return priors;
}

}  // namespace arucoslam
