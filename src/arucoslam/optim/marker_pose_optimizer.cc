#include "arucoslam/optim/marker_pose_optimizer.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "arucoslam/markers/marker_pose.h"

namespace arucoslam {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct Normal {
  Matrix6d hessian = Matrix6d::Zero();
  Vector6d gradient = Vector6d::Zero();
  double cost = 0.0;
  int count = 0;  // residual blocks in front of the camera
};

// Huber cost of a whitened squared norm and its IRLS weight.
double Huber(double squared, double delta, bool robust, double* weight) {
  *weight = 1.0;
  if (!robust || squared <= delta * delta) return squared;
  const double e = std::sqrt(squared);
  *weight = delta / e;
  return 2.0 * delta * e - delta * delta;
}

// The problem of one frame: the error terms and which are active.
struct FrameProblem {
  const std::vector<PoseObservation>& observations;
  std::vector<MarkerCornerError> marker_errors;
  std::vector<double> marker_information;
  const std::vector<MarkerPoseObservation>& markers;
  const PinholeIntrinsics& intrinsics;
  const MarkerPoseOptimizationOptions& options;
  std::vector<bool> active;         // keypoints
  std::vector<bool> marker_active;  // markers

  // Whitened squared error of keypoint i, or -1 when behind the camera (with Jacobian).
  // `rotation` is pose's rotation matrix (computed once per pass over the observations).
  double Keypoint(std::size_t i, const Rigid3& pose, const Eigen::Matrix3d& rotation,
                  Eigen::Vector2d* r, PoseJacobian* j) const {
    if (!ReprojectionError(intrinsics, observations[i].pixel)
             .Evaluate(rotation, pose.translation, observations[i].p_in_world, r, j, nullptr)) {
      return -1.0;
    }
    return r->squaredNorm() / (observations[i].sigma_px * observations[i].sigma_px);
  }
  double Marker(std::size_t i, const Rigid3& pose, Vector8d* r, MarkerCornerJacobian* j) const {
    if (!marker_errors[i].Evaluate(pose, markers[i].world_from_marker, r, j)) return -1.0;
    return marker_information[i] * r->squaredNorm();
  }

  Normal Accumulate(const Rigid3& pose, bool robust, bool jacobians) const {
    Normal normal;
    const double behind_cost = 2e3 * options.keypoints.huber_delta;
    const Eigen::Matrix3d rotation = pose.RotationMatrix();
    for (std::size_t i = 0; i < observations.size(); ++i) {
      if (!active[i]) continue;
      Eigen::Vector2d r;
      PoseJacobian j;
      const double chi2 = Keypoint(i, pose, rotation, &r, jacobians ? &j : nullptr);
      if (chi2 < 0.0) {
        normal.cost += behind_cost;
        continue;
      }
      double weight;
      normal.cost += Huber(chi2, options.keypoints.huber_delta, robust, &weight);
      ++normal.count;
      if (!jacobians) continue;
      const double w = weight / (observations[i].sigma_px * observations[i].sigma_px);
      normal.hessian.noalias() += w * j.transpose() * j;
      normal.gradient.noalias() += w * j.transpose() * r;
    }
    for (std::size_t i = 0; i < markers.size(); ++i) {
      if (!marker_active[i]) continue;
      Vector8d r;
      MarkerCornerJacobian j;
      const double chi2 = Marker(i, pose, &r, jacobians ? &j : nullptr);
      if (chi2 < 0.0) {
        normal.cost += behind_cost;
        continue;
      }
      double weight;
      normal.cost += Huber(chi2, options.marker_huber_delta, robust, &weight);
      normal.count += 4;
      if (!jacobians) continue;
      const double w = weight * marker_information[i];
      normal.hessian.noalias() += w * j.transpose() * j;
      normal.gradient.noalias() += w * j.transpose() * r;
    }
    return normal;
  }

  Rigid3 Round(Rigid3 pose, bool robust) const {
    double lambda = 1e-4;
    for (int iteration = 0; iteration < options.keypoints.iterations_per_round; ++iteration) {
      const Normal normal = Accumulate(pose, robust, true);
      if (normal.count < 3) break;
      bool improved = false;
      for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
        Matrix6d damped = normal.hessian;
        damped.diagonal() += lambda * (normal.hessian.diagonal().array() + 1e-9).matrix();
        const Vector6d step = -damped.ldlt().solve(normal.gradient);
        if (!step.allFinite()) return pose;
        const Rigid3 candidate = Rigid3::Exp(step) * pose;
        const double cost = Accumulate(candidate, robust, false).cost;
        if (cost < normal.cost) {
          pose = candidate;
          lambda = std::max(lambda / 10.0, 1e-9);
          improved = true;
          if (step.norm() < 1e-10 || normal.cost - cost < 1e-12 * normal.cost) return pose;
        } else {
          lambda *= 10.0;
        }
      }
      if (!improved) break;
    }
    return pose;
  }
};

}  // namespace

MarkerPoseOptimizationResult OptimizePoseWithMarkers(
    const std::vector<PoseObservation>& observations,
    const std::vector<MarkerPoseObservation>& markers, const Rigid3& initial_cam_from_world,
    const PinholeIntrinsics& intrinsics, const MarkerPoseOptimizationOptions& options) {
  FrameProblem problem{observations, {}, {}, markers, intrinsics, options, {}, {}};
  for (const MarkerPoseObservation& marker : markers) {
    problem.marker_errors.emplace_back(intrinsics, SquareCorners(marker.size), marker.corners_px);
    problem.marker_information.push_back(1.0 / (marker.sigma_px * marker.sigma_px));
  }
  problem.active.assign(observations.size(), true);
  problem.marker_active.assign(markers.size(), true);
  MarkerPoseOptimizationResult result;
  result.cam_from_world = initial_cam_from_world;
  for (int round = 0; round < options.keypoints.num_rounds; ++round) {
    const bool robust = round < options.keypoints.num_robust_rounds;
    result.cam_from_world = problem.Round(result.cam_from_world, robust);
    result.num_inliers = 0;
    result.num_marker_inliers = 0;
    const Eigen::Matrix3d rotation = result.cam_from_world.RotationMatrix();
    for (std::size_t i = 0; i < observations.size(); ++i) {
      Eigen::Vector2d r;
      const double chi2 = problem.Keypoint(i, result.cam_from_world, rotation, &r, nullptr);
      problem.active[i] = chi2 >= 0.0 && chi2 <= options.keypoints.chi_square_threshold;
      result.num_inliers += problem.active[i] ? 1 : 0;
    }
    for (std::size_t i = 0; i < markers.size(); ++i) {
      Vector8d r;
      const double chi2 = problem.Marker(i, result.cam_from_world, &r, nullptr);
      problem.marker_active[i] = chi2 >= 0.0 && chi2 <= options.marker_chi_square_threshold;
      result.num_marker_inliers += problem.marker_active[i] ? 1 : 0;
    }
    if (result.num_inliers < options.keypoints.min_inliers && result.num_marker_inliers == 0) {
      break;
    }
  }
  result.inliers = problem.active;
  result.marker_inliers = problem.marker_active;
  result.success =
      result.num_inliers >= options.keypoints.min_inliers || result.num_marker_inliers > 0;
  double sum = 0.0, marker_sum = 0.0;
  const Eigen::Matrix3d rotation = result.cam_from_world.RotationMatrix();
  for (std::size_t i = 0; i < observations.size(); ++i) {
    Eigen::Vector2d r;
    if (problem.active[i] &&
        problem.Keypoint(i, result.cam_from_world, rotation, &r, nullptr) >= 0.0) {
      sum += r.squaredNorm();
    }
  }
  for (std::size_t i = 0; i < markers.size(); ++i) {
    Vector8d r;
    if (problem.marker_active[i] && problem.Marker(i, result.cam_from_world, &r, nullptr) >= 0.0) {
      marker_sum += r.squaredNorm();
    }
  }
  if (result.num_inliers > 0) result.final_rms_px = std::sqrt(sum / result.num_inliers);
  if (result.num_marker_inliers > 0) {
    result.final_marker_rms_px = std::sqrt(marker_sum / (4.0 * result.num_marker_inliers));
  }
  return result;
}

}  // namespace arucoslam
