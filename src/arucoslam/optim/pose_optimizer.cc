#include "arucoslam/optim/pose_optimizer.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// Weighted normal equations and robust cost of the active observations at one pose.
struct NormalEquations {
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  Vector6d gradient = Vector6d::Zero();
  double cost = 0.0;
  int count = 0;
};

// Huber cost of a whitened squared error s = e^2 and its IRLS weight.
void Huber(double squared, double delta, bool robust, double* cost, double* weight) {
  if (!robust || squared <= delta * delta) {
    *cost = squared;
    *weight = 1.0;
    return;
  }
  const double e = std::sqrt(squared);
  *cost = 2.0 * delta * e - delta * delta;
  *weight = delta / e;
}

NormalEquations Accumulate(const std::vector<PoseObservation>& observations,
                           const std::vector<bool>& active, const Rigid3& cam_from_world,
                           const PinholeIntrinsics& intrinsics, double delta, bool robust,
                           bool with_jacobians) {
  NormalEquations equations;
  const Eigen::Matrix3d rotation = cam_from_world.RotationMatrix();
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (!active[i]) continue;
    const PoseObservation& observation = observations[i];
    const ReprojectionError error(intrinsics, observation.pixel);
    Eigen::Vector2d residual;
    PoseJacobian jacobian;
    if (!error.Evaluate(rotation, cam_from_world.translation, observation.p_in_world, &residual,
                        with_jacobians ? &jacobian : nullptr, nullptr)) {
      // Behind the camera: a large constant cost so that such a step is never preferred.
      equations.cost += 2.0 * delta * 1e3;
      continue;
    }
    const double information = 1.0 / (observation.sigma_px * observation.sigma_px);
    double cost = 0.0, weight = 1.0;
    Huber(information * residual.squaredNorm(), delta, robust, &cost, &weight);
    equations.cost += cost;
    ++equations.count;
    if (with_jacobians) {
      const double w = weight * information;
      equations.hessian.noalias() += w * jacobian.transpose() * jacobian;
      equations.gradient.noalias() += w * jacobian.transpose() * residual;
    }
  }
  return equations;
}

// Levenberg-Marquardt on the active observations; returns the improved pose.
Rigid3 RunRound(const std::vector<PoseObservation>& observations, const std::vector<bool>& active,
                Rigid3 cam_from_world, const PinholeIntrinsics& intrinsics,
                const PoseOptimizationOptions& options, bool robust) {
  double lambda = 1e-4;
  for (int iteration = 0; iteration < options.iterations_per_round; ++iteration) {
    const NormalEquations equations = Accumulate(observations, active, cam_from_world, intrinsics,
                                                 options.huber_delta, robust, true);
    if (equations.count < 3) break;
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::Matrix<double, 6, 6> damped = equations.hessian;
      damped.diagonal() += lambda * (equations.hessian.diagonal().array() + 1e-9).matrix();
      const Vector6d step = -damped.ldlt().solve(equations.gradient);
      if (!step.allFinite()) break;
      const Rigid3 candidate = Rigid3::Exp(step) * cam_from_world;
      const double cost = Accumulate(observations, active, candidate, intrinsics,
                                     options.huber_delta, robust, false)
                              .cost;
      if (cost < equations.cost) {
        cam_from_world = candidate;
        lambda = std::max(lambda / 10.0, 1e-9);
        improved = true;
        if (step.norm() < 1e-10 || equations.cost - cost < 1e-12 * equations.cost)
          return cam_from_world;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) break;
  }
  return cam_from_world;
}

// Squared whitened error per observation; negative when behind the camera.
double WhitenedSquaredError(const PoseObservation& observation, const Rigid3& cam_from_world,
                            const PinholeIntrinsics& intrinsics) {
  Eigen::Vector2d residual;
  if (!ReprojectionError(intrinsics, observation.pixel)
           .Evaluate(cam_from_world, observation.p_in_world, &residual)) {
    return -1.0;
  }
  return residual.squaredNorm() / (observation.sigma_px * observation.sigma_px);
}

double RmsPixels(const std::vector<PoseObservation>& observations, const std::vector<bool>& use,
                 const Rigid3& cam_from_world, const PinholeIntrinsics& intrinsics) {
  double sum = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (!use[i]) continue;
    Eigen::Vector2d residual;
    if (ReprojectionError(intrinsics, observations[i].pixel)
            .Evaluate(cam_from_world, observations[i].p_in_world, &residual)) {
      sum += residual.squaredNorm();
      ++count;
    }
  }
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

}  // namespace

bool PoseOptimizationOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("num_rounds", num_rounds, 1);
  check.AtLeast("iterations_per_round", iterations_per_round, 1);
  check.AtLeast("num_robust_rounds", num_robust_rounds, 0);
  check.Above("huber_delta", huber_delta, 0.0);
  check.Above("chi_square_threshold", chi_square_threshold, 0.0);
  check.AtLeast("min_inliers", min_inliers, 3);
  return check.ok();
}

PoseOptimizationResult OptimizePose(const std::vector<PoseObservation>& observations,
                                    const Rigid3& initial_cam_from_world,
                                    const PinholeIntrinsics& intrinsics,
                                    const PoseOptimizationOptions& options) {
  PoseOptimizationResult result;
  result.cam_from_world = initial_cam_from_world;
  std::vector<bool> active(observations.size(), true);
  result.initial_rms_px = RmsPixels(observations, active, initial_cam_from_world, intrinsics);
  for (int round = 0; round < options.num_rounds; ++round) {
    const bool robust = round < options.num_robust_rounds;
    result.cam_from_world =
        RunRound(observations, active, result.cam_from_world, intrinsics, options, robust);
    // Re-classify every observation, outliers of earlier rounds included.
    int num_inliers = 0;
    for (std::size_t i = 0; i < observations.size(); ++i) {
      const double chi2 = WhitenedSquaredError(observations[i], result.cam_from_world, intrinsics);
      active[i] = chi2 >= 0.0 && chi2 <= options.chi_square_threshold;
      num_inliers += active[i] ? 1 : 0;
    }
    result.num_inliers = num_inliers;
    if (num_inliers < options.min_inliers) break;
  }
  result.inliers = active;
  result.success = result.num_inliers >= options.min_inliers;
  result.final_rms_px = RmsPixels(observations, active, result.cam_from_world, intrinsics);
  return result;
}

}  // namespace arucoslam
