// SolveBundleAdjustment: Levenberg-Marquardt with an explicit Schur complement over the points.
#include "arucoslam/optim/bundle_adjustment.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <vector>

#include "arucoslam/util/timing.h"

namespace arucoslam {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix63d = Eigen::Matrix<double, 6, 3>;

// Trust-region constants as Ceres' Levenberg-Marquardt uses them, so that both solvers take
// the same path to the optimum.
constexpr double kInitialRadius = 1e4;
constexpr double kMaxRadius = 1e16;
constexpr double kMinRadius = 1e-32;
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr double kParameterTolerance = 1e-8;
constexpr double kGradientTolerance = 1e-10;

// Huber on the squared whitened residual s: half the robust cost, and its slope (the weight
// of the reweighted least squares).
struct Robust {
  double half_cost = 0.0;
  double weight = 0.0;
};

Robust Huber(double s, double delta) {
  if (s <= delta * delta) return {0.5 * s, 1.0};
  const double root = std::sqrt(s);
  return {delta * root - 0.5 * delta * delta, delta / root};
}

// Which poses are free (their block in the reduced system) and which observations each point
// has, with the free-pose block of each.
struct Layout {
  std::vector<int> free_pose;  // pose -> block index, -1 when fixed or unobserved
  int num_free_poses = 0;
  std::vector<std::vector<int>> point_observations;
  std::vector<bool> point_free;  // not fixed and observed

  explicit Layout(const BundleAdjustmentProblem& problem)
      : free_pose(problem.poses.size(), -1),
        point_observations(problem.points.size()),
        point_free(problem.points.size(), false) {
    std::vector<bool> observed(problem.poses.size(), false);
    for (std::size_t k = 0; k < problem.observations.size(); ++k) {
      const auto& observation = problem.observations[k];
      observed[observation.pose_index] = true;
      point_observations[observation.point_index].push_back(static_cast<int>(k));
    }
    for (std::size_t i = 0; i < problem.poses.size(); ++i) {
      if (observed[i] && !problem.poses[i].fixed) free_pose[i] = num_free_poses++;
    }
    for (std::size_t j = 0; j < problem.points.size(); ++j) {
      point_free[j] = !problem.points[j].fixed && !point_observations[j].empty();
    }
  }
};

struct Estimate {
  std::vector<Rigid3> poses;
  std::vector<Eigen::Vector3d> points;
};

// One observation linearised at the current estimate.
struct LinearTerm {
  bool in_front = false;
  Eigen::Vector2d residual = Eigen::Vector2d::Zero();
  PoseJacobian d_pose = PoseJacobian::Zero();
  PointJacobian d_point = PointJacobian::Zero();
  double weight = 0.0;  // Huber slope / sigma^2
};

// The undamped normal equations at the current estimate: blocks of J^T W J and J^T W r.
struct NormalEquations {
  std::vector<Matrix6d> pose_hessian;  // per free pose
  std::vector<Vector6d> pose_gradient;
  std::vector<Eigen::Matrix3d> point_hessian;  // per point
  std::vector<Eigen::Vector3d> point_gradient;
  std::vector<Matrix63d> coupling;  // per observation of a free pose and a free point
};

double TotalCost(const BundleAdjustmentProblem& problem, const Estimate& estimate, double delta) {
  double cost = 0.0;
  for (const auto& observation : problem.observations) {
    Eigen::Vector2d residual;
    if (!ReprojectionError(problem.intrinsics, observation.pixel)
             .Evaluate(estimate.poses[observation.pose_index],
                       estimate.points[observation.point_index], &residual)) {
      continue;
    }
    const double s = residual.squaredNorm() / (observation.sigma_px * observation.sigma_px);
    cost += Huber(s, delta).half_cost;
  }
  return cost;
}

void Linearize(const BundleAdjustmentProblem& problem, const Layout& layout,
               const Estimate& estimate, double delta, std::vector<LinearTerm>* terms,
               NormalEquations* equations) {
  equations->pose_hessian.assign(layout.num_free_poses, Matrix6d::Zero());
  equations->pose_gradient.assign(layout.num_free_poses, Vector6d::Zero());
  equations->point_hessian.assign(problem.points.size(), Eigen::Matrix3d::Zero());
  equations->point_gradient.assign(problem.points.size(), Eigen::Vector3d::Zero());
  equations->coupling.resize(problem.observations.size());
  std::vector<Eigen::Matrix3d> rotations(estimate.poses.size());
  for (std::size_t i = 0; i < estimate.poses.size(); ++i) {
    rotations[i] = estimate.poses[i].RotationMatrix();
  }
  for (std::size_t k = 0; k < problem.observations.size(); ++k) {
    const auto& observation = problem.observations[k];
    LinearTerm& term = (*terms)[k];
    term.in_front = ReprojectionError(problem.intrinsics, observation.pixel)
                        .Evaluate(rotations[observation.pose_index],
                                  estimate.poses[observation.pose_index].translation,
                                  estimate.points[observation.point_index], &term.residual,
                                  &term.d_pose, &term.d_point);
    if (!term.in_front) continue;
    const double inverse_variance = 1.0 / (observation.sigma_px * observation.sigma_px);
    term.weight =
        inverse_variance * Huber(term.residual.squaredNorm() * inverse_variance, delta).weight;
    const int block = layout.free_pose[observation.pose_index];
    if (block >= 0) {
      equations->pose_hessian[block].noalias() += term.weight * term.d_pose.transpose() * term.d_pose;
      equations->pose_gradient[block].noalias() +=
          term.weight * term.d_pose.transpose() * term.residual;
    }
    if (layout.point_free[observation.point_index]) {
      equations->point_hessian[observation.point_index].noalias() +=
          term.weight * term.d_point.transpose() * term.d_point;
      equations->point_gradient[observation.point_index].noalias() +=
          term.weight * term.d_point.transpose() * term.residual;
      if (block >= 0) {
        equations->coupling[k].noalias() = term.weight * term.d_pose.transpose() * term.d_point;
      }
    }
  }
}

template <typename Diagonal>
Diagonal Damping(const Diagonal& diagonal, double radius) {
  return diagonal.cwiseMax(kMinDiagonal).cwiseMin(kMaxDiagonal) / radius;
}

// The damped step (H + D / radius) step = -g, points eliminated. False when the reduced
// system is not positive definite.
struct Step {
  Eigen::VectorXd poses;  // 6 per free pose
  std::vector<Eigen::Vector3d> points;
  double model_decrease = 0.0;  // decrease of the linearised cost
};

bool SolveDampedStep(const BundleAdjustmentProblem& problem, const Layout& layout,
                     const std::vector<LinearTerm>& terms, const NormalEquations& equations,
                     double radius, Eigen::MatrixXd* reduced, Step* step) {
  const int n = 6 * layout.num_free_poses;
  reduced->setZero(n, n);
  Eigen::VectorXd rhs(n);
  double model_decrease = 0.0;
  for (int f = 0; f < layout.num_free_poses; ++f) {
    const Vector6d damping = Damping(Vector6d(equations.pose_hessian[f].diagonal()), radius);
    reduced->block<6, 6>(6 * f, 6 * f) = equations.pose_hessian[f];
    reduced->block<6, 6>(6 * f, 6 * f).diagonal() += damping;
    rhs.segment<6>(6 * f) = -equations.pose_gradient[f];
  }
  std::vector<Eigen::Matrix3d> point_inverse(problem.points.size());
  std::vector<Matrix63d> scaled;  // coupling x point inverse, per free observation of a point
  std::vector<int> scaled_block;
  std::vector<int> scaled_term;
  for (std::size_t j = 0; j < problem.points.size(); ++j) {
    if (!layout.point_free[j]) continue;
    Eigen::Matrix3d damped = equations.point_hessian[j];
    damped.diagonal() += Damping(Eigen::Vector3d(damped.diagonal()), radius);
    point_inverse[j] = damped.inverse();
    scaled.clear();
    scaled_block.clear();
    scaled_term.clear();
    for (int k : layout.point_observations[j]) {
      const int block = layout.free_pose[problem.observations[k].pose_index];
      if (!terms[k].in_front || block < 0) continue;
      scaled.push_back(equations.coupling[k] * point_inverse[j]);
      scaled_block.push_back(block);
      scaled_term.push_back(k);
    }
    for (std::size_t a = 0; a < scaled.size(); ++a) {
      rhs.segment<6>(6 * scaled_block[a]).noalias() += scaled[a] * equations.point_gradient[j];
      for (std::size_t b = 0; b < scaled.size(); ++b) {
        if (scaled_block[b] < scaled_block[a]) continue;
        reduced->block<6, 6>(6 * scaled_block[a], 6 * scaled_block[b]).noalias() -=
            scaled[a] * equations.coupling[scaled_term[b]].transpose();
      }
    }
  }
  const Eigen::LLT<Eigen::MatrixXd, Eigen::Upper> cholesky(*reduced);
  if (n > 0 && cholesky.info() != Eigen::Success) return false;
  step->poses = n > 0 ? cholesky.solve(rhs) : Eigen::VectorXd();
  if (n > 0 && !step->poses.allFinite()) return false;
  for (int f = 0; f < layout.num_free_poses; ++f) {
    const Vector6d part = step->poses.segment<6>(6 * f);
    const Vector6d damping = Damping(Vector6d(equations.pose_hessian[f].diagonal()), radius);
    model_decrease += -equations.pose_gradient[f].dot(part) + part.dot(damping.cwiseProduct(part));
  }
  step->points.assign(problem.points.size(), Eigen::Vector3d::Zero());
  for (std::size_t j = 0; j < problem.points.size(); ++j) {
    if (!layout.point_free[j]) continue;
    Eigen::Vector3d right = -equations.point_gradient[j];
    for (int k : layout.point_observations[j]) {
      const int block = layout.free_pose[problem.observations[k].pose_index];
      if (!terms[k].in_front || block < 0) continue;
      right.noalias() -= equations.coupling[k].transpose() * step->poses.segment<6>(6 * block);
    }
    const Eigen::Vector3d part = point_inverse[j] * right;
    const Eigen::Vector3d damping =
        Damping(Eigen::Vector3d(equations.point_hessian[j].diagonal()), radius);
    step->points[j] = part;
    model_decrease += -equations.point_gradient[j].dot(part) + part.dot(damping.cwiseProduct(part));
  }
  step->model_decrease = 0.5 * model_decrease;
  return std::isfinite(step->model_decrease);
}

Estimate Moved(const Estimate& estimate, const Layout& layout, const Step& step) {
  Estimate moved = estimate;
  for (std::size_t i = 0; i < moved.poses.size(); ++i) {
    const int block = layout.free_pose[i];
    if (block >= 0) moved.poses[i] = Rigid3::Exp(step.poses.segment<6>(6 * block)) * moved.poses[i];
  }
  for (std::size_t j = 0; j < moved.points.size(); ++j) {
    if (layout.point_free[j]) moved.points[j] += step.points[j];
  }
  return moved;
}

double StepNorm(const Layout& layout, const Step& step) {
  double squared = step.poses.squaredNorm();
  for (std::size_t j = 0; j < step.points.size(); ++j) {
    if (layout.point_free[j]) squared += step.points[j].squaredNorm();
  }
  return std::sqrt(squared);
}

double ParameterNorm(const Estimate& estimate, const Layout& layout) {
  double squared = 0.0;
  for (std::size_t i = 0; i < estimate.poses.size(); ++i) {
    if (layout.free_pose[i] < 0) continue;
    squared += estimate.poses[i].rotation.coeffs().squaredNorm() +
               estimate.poses[i].translation.squaredNorm();
  }
  for (std::size_t j = 0; j < estimate.points.size(); ++j) {
    if (layout.point_free[j]) squared += estimate.points[j].squaredNorm();
  }
  return std::sqrt(squared);
}

double GradientMaxNorm(const NormalEquations& equations, const Layout& layout) {
  double norm = 0.0;
  for (const Vector6d& gradient : equations.pose_gradient) {
    norm = std::max(norm, gradient.cwiseAbs().maxCoeff());
  }
  for (std::size_t j = 0; j < equations.point_gradient.size(); ++j) {
    if (layout.point_free[j]) norm = std::max(norm, equations.point_gradient[j].cwiseAbs().maxCoeff());
  }
  return norm;
}

}  // namespace

BundleAdjustmentSummary SolveBundleAdjustment(const BundleAdjustmentOptions& options,
                                              BundleAdjustmentProblem* problem) {
  BundleAdjustmentSummary summary;
  std::string reason;
  if (!options.Check()) {
    summary.message = "invalid options";
    return summary;
  }
  if (!problem->Check(&reason)) {
    summary.message = reason;
    return summary;
  }
  const Stopwatch stopwatch;
  summary.num_residual_blocks = static_cast<int>(problem->observations.size());
  summary.initial_rms_px = ReprojectionRmsPixels(*problem);
  if (problem->observations.empty()) {
    summary.success = true;
    summary.message = "no observations";
    return summary;
  }
  const Layout layout(*problem);
  const double delta = options.huber_delta_px;
  Estimate estimate;
  for (const auto& pose : problem->poses) estimate.poses.push_back(pose.cam_from_world);
  for (const auto& point : problem->points) estimate.points.push_back(point.p_in_world);

  std::vector<LinearTerm> terms(problem->observations.size());
  NormalEquations equations;
  Eigen::MatrixXd reduced;
  Step step;
  double cost = TotalCost(*problem, estimate, delta);
  summary.initial_cost = cost;
  double radius = kInitialRadius;
  double decrease_factor = 2.0;
  bool relinearize = true;
  summary.message = "maximum iterations";
  for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
    if (relinearize) {
      Linearize(*problem, layout, estimate, delta, &terms, &equations);
      relinearize = false;
      if (GradientMaxNorm(equations, layout) <= kGradientTolerance) {
        summary.message = "gradient tolerance";
        break;
      }
    }
    summary.num_iterations = iteration;
    bool accepted = false;
    bool converged = false;
    if (SolveDampedStep(*problem, layout, terms, equations, radius, &reduced, &step)) {
      const double step_norm = StepNorm(layout, step);
      if (step_norm <= kParameterTolerance * (ParameterNorm(estimate, layout) + kParameterTolerance)) {
        summary.message = "parameter tolerance";
        break;
      }
      Estimate moved = Moved(estimate, layout, step);
      const double moved_cost = TotalCost(*problem, moved, delta);
      const double ratio =
          step.model_decrease > 0.0 ? (cost - moved_cost) / step.model_decrease : -1.0;
      if (ratio > kMinRelativeDecrease) {
        accepted = true;
        converged = (cost - moved_cost) <= options.function_tolerance * cost;
        estimate = std::move(moved);
        cost = moved_cost;
        relinearize = true;
        const double shrink = 1.0 - std::pow(2.0 * ratio - 1.0, 3);
        radius = std::min(kMaxRadius, radius / std::max(1.0 / 3.0, shrink));
        decrease_factor = 2.0;
      }
    }
    if (!accepted) {
      radius /= decrease_factor;
      decrease_factor *= 2.0;
      if (radius < kMinRadius) {
        summary.message = "trust region too small";
        break;
      }
    }
    if (converged) {
      summary.message = "function tolerance";
      break;
    }
    if (options.stop_requested && iteration >= options.min_iterations_before_stop &&
        options.stop_requested()) {
      summary.stopped_early = true;
      summary.message = "stop requested";
      break;
    }
  }
  summary.success = true;
  summary.final_cost = cost;
  for (std::size_t i = 0; i < problem->poses.size(); ++i) {
    if (layout.free_pose[i] >= 0) problem->poses[i].cam_from_world = estimate.poses[i];
  }
  for (std::size_t j = 0; j < problem->points.size(); ++j) {
    if (layout.point_free[j]) problem->points[j].p_in_world = estimate.points[j];
  }
  summary.final_rms_px = ReprojectionRmsPixels(*problem);
  summary.outliers =
      FlagReprojectionOutliers(*problem, options.chi_square_threshold, &summary.num_outliers);
  summary.solve_seconds = stopwatch.ElapsedSeconds();
  return summary;
}

}  // namespace arucoslam
