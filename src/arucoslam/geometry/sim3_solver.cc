#include "arucoslam/geometry/sim3_solver.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>

#include "arucoslam/geometry/umeyama.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

constexpr double kMinDepth = 1e-6;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Pinhole projection to an undistorted pixel; false behind the camera.
bool ProjectPinhole(const CameraModel& camera, const Eigen::Vector3d& p_in_cam,
                    Eigen::Vector2d* pixel) {
  if (p_in_cam.z() < kMinDepth) return false;
  *pixel = Eigen::Vector2d(camera.fx * p_in_cam.x() / p_in_cam.z() + camera.cx,
                           camera.fy * p_in_cam.y() / p_in_cam.z() + camera.cy);
  return true;
}

// Whitened residuals (4: candidate image then current image); false if behind a camera.
bool WhitenedResiduals(const CameraModel& current_camera, const CameraModel& candidate_camera,
                       const Sim3Correspondence& c, const Sim3& candidate_from_current,
                       const Sim3& current_from_candidate, Eigen::Vector4d* residual) {
  Eigen::Vector2d in_candidate, in_current;
  if (!ProjectPinhole(candidate_camera, candidate_from_current * c.p_in_current, &in_candidate) ||
      !ProjectPinhole(current_camera, current_from_candidate * c.p_in_candidate, &in_current)) {
    return false;
  }
  residual->head<2>() = (in_candidate - c.pixel_in_candidate) / c.sigma_candidate_px;
  residual->tail<2>() = (in_current - c.pixel_in_current) / c.sigma_current_px;
  return true;
}

struct InlierSet {
  std::vector<bool> inliers;
  int count = 0;
};

InlierSet CountInliers(const CameraModel& current_camera, const CameraModel& candidate_camera,
                       const std::vector<Sim3Correspondence>& correspondences, const Sim3& model,
                       double threshold) {
  InlierSet set;
  set.inliers.assign(correspondences.size(), false);
  for (std::size_t i = 0; i < correspondences.size(); ++i) {
    const Eigen::Vector2d chi2 =
        Sim3ChiSquares(current_camera, candidate_camera, correspondences[i], model);
    if (chi2.maxCoeff() < threshold) {
      set.inliers[i] = true;
      ++set.count;
    }
  }
  return set;
}

std::optional<Sim3> FitSubset(const std::vector<Sim3Correspondence>& correspondences,
                              const std::vector<std::size_t>& subset, bool fix_scale) {
  std::vector<Eigen::Vector3d> source, target;
  for (std::size_t index : subset) {
    source.push_back(correspondences[index].p_in_current);
    target.push_back(correspondences[index].p_in_candidate);
  }
  return UmeyamaAlignment(source, target,
                          fix_scale ? AlignmentKind::kRigid : AlignmentKind::kSimilarity);
}

// Robust cost (Huber) of the inliers and its IRLS normal equations by central differences
// in the left tangent: candidate_from_current <- Exp(delta) * candidate_from_current.
struct RefineProblem {
  const CameraModel& current_camera;
  const CameraModel& candidate_camera;
  std::vector<const Sim3Correspondence*> matches;
  double huber_delta;
  int dof;  // 7, or 6 with the scale fixed

  double Cost(const Sim3& model) const {
    const Sim3 inverse = model.Inverse();
    double cost = 0.0;
    for (const Sim3Correspondence* c : matches) {
      Eigen::Vector4d r;
      if (!WhitenedResiduals(current_camera, candidate_camera, *c, model, inverse, &r)) {
        cost += huber_delta * huber_delta * 4.0;  // behind a camera: a large, flat penalty
        continue;
      }
      for (int k = 0; k < 4; ++k) {
        const double a = std::abs(r[k]);
        cost += a <= huber_delta ? a * a : 2.0 * huber_delta * a - huber_delta * huber_delta;
      }
    }
    return cost;
  }

  Sim3 Perturb(const Sim3& model, const Eigen::VectorXd& delta) const {
    Vector7d tangent = Vector7d::Zero();
    tangent.head(dof) = delta;
    return Sim3::Exp(tangent) * model;
  }

  void NormalEquations(const Sim3& model, Eigen::MatrixXd* hessian,
                       Eigen::VectorXd* gradient) const {
    constexpr double kStep = 1e-6;
    hessian->setZero(dof, dof);
    gradient->setZero(dof);
    std::vector<Sim3> plus(dof), minus(dof), plus_inverse(dof), minus_inverse(dof);
    for (int j = 0; j < dof; ++j) {
      Eigen::VectorXd step = Eigen::VectorXd::Zero(dof);
      step[j] = kStep;
      plus[j] = Perturb(model, step);
      minus[j] = Perturb(model, -step);
      plus_inverse[j] = plus[j].Inverse();
      minus_inverse[j] = minus[j].Inverse();
    }
    const Sim3 inverse = model.Inverse();
    for (const Sim3Correspondence* c : matches) {
      Eigen::Vector4d r, r_plus, r_minus;
      if (!WhitenedResiduals(current_camera, candidate_camera, *c, model, inverse, &r)) continue;
      Eigen::Matrix<double, 4, Eigen::Dynamic> jacobian(4, dof);
      bool valid = true;
      for (int j = 0; j < dof && valid; ++j) {
        valid = WhitenedResiduals(current_camera, candidate_camera, *c, plus[j], plus_inverse[j],
                                  &r_plus) &&
                WhitenedResiduals(current_camera, candidate_camera, *c, minus[j], minus_inverse[j],
                                  &r_minus);
        jacobian.col(j) = (r_plus - r_minus) / (2.0 * kStep);
      }
      if (!valid) continue;
      for (int k = 0; k < 4; ++k) {
        const double a = std::abs(r[k]);
        const double weight = a <= huber_delta ? 1.0 : huber_delta / a;
        *hessian += weight * jacobian.row(k).transpose() * jacobian.row(k);
        *gradient += weight * jacobian.row(k).transpose() * r[k];
      }
    }
  }
};

Sim3 Refine(const RefineProblem& problem, const Sim3& initial, int iterations) {
  Sim3 model = initial;
  double cost = problem.Cost(model);
  double lambda = 1e-4;
  Eigen::MatrixXd hessian;
  Eigen::VectorXd gradient;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    problem.NormalEquations(model, &hessian, &gradient);
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::MatrixXd damped = hessian;
      damped.diagonal() += lambda * hessian.diagonal().cwiseMax(1e-9);
      const Eigen::VectorXd delta = damped.ldlt().solve(-gradient);
      if (!delta.allFinite()) break;
      const Sim3 candidate = problem.Perturb(model, delta);
      const double candidate_cost = problem.Cost(candidate);
      if (candidate_cost < cost) {
        const double relative_decrease = (cost - candidate_cost) / std::max(cost, 1e-300);
        model = candidate;
        cost = candidate_cost;
        lambda = std::max(lambda / 10.0, 1e-12);
        improved = true;
        if (relative_decrease < 1e-10) return model;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) break;
  }
  return model;
}

double InlierRms(const CameraModel& current_camera, const CameraModel& candidate_camera,
                 const std::vector<Sim3Correspondence>& correspondences,
                 const std::vector<bool>& inliers, const Sim3& model) {
  const Sim3 inverse = model.Inverse();
  double sum = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < correspondences.size(); ++i) {
    if (!inliers[i]) continue;
    Eigen::Vector4d r;
    if (!WhitenedResiduals(current_camera, candidate_camera, correspondences[i], model, inverse,
                           &r)) {
      continue;
    }
    r.head<2>() *= correspondences[i].sigma_candidate_px;
    r.tail<2>() *= correspondences[i].sigma_current_px;
    sum += r.squaredNorm();
    count += 2;
  }
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

// Distance between the two camera centres (candidate frame) over the inliers' median depth in
// the candidate camera; 0 without inliers.
double BaselineDepthRatio(const std::vector<Sim3Correspondence>& correspondences,
                          const std::vector<bool>& inliers, const Sim3& candidate_from_current) {
  std::vector<double> depths;
  for (std::size_t i = 0; i < correspondences.size(); ++i) {
    if (inliers[i]) depths.push_back(correspondences[i].p_in_candidate.z());
  }
  if (depths.empty()) return 0.0;
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  const double median = depths[depths.size() / 2];
  return median > 0.0 ? candidate_from_current.translation.norm() / median : 0.0;
}

// RANSAC over minimal samples; returns the best model and its inlier count.
std::optional<Sim3> Ransac(const CameraModel& current_camera, const CameraModel& candidate_camera,
                           const std::vector<Sim3Correspondence>& correspondences,
                           const Sim3SolverOptions& options, Sim3SolverResult* result) {
  std::mt19937 random(options.seed);
  std::uniform_int_distribution<std::size_t> pick(0, correspondences.size() - 1);
  std::optional<Sim3> best;
  int best_count = 0;
  int needed = options.max_ransac_iterations;
  int iteration = 0;
  for (; iteration < std::min(needed, options.max_ransac_iterations); ++iteration) {
    std::vector<std::size_t> subset;
    while (subset.size() < 3) {
      const std::size_t index = pick(random);
      if (std::find(subset.begin(), subset.end(), index) == subset.end()) subset.push_back(index);
    }
    const std::optional<Sim3> model = FitSubset(correspondences, subset, options.fix_scale);
    if (!model) continue;
    const InlierSet set = CountInliers(current_camera, candidate_camera, correspondences, *model,
                                       options.chi_square_threshold);
    if (set.count <= best_count) continue;
    best_count = set.count;
    best = model;
    const double inlier_ratio = static_cast<double>(set.count) / correspondences.size();
    const double all_inlier = std::pow(inlier_ratio, 3);
    if (all_inlier >= 1.0 - 1e-12) {
      needed = iteration + 1;
    } else {
      needed = static_cast<int>(
          std::ceil(std::log(1.0 - options.confidence) / std::log(1.0 - all_inlier)));
    }
  }
  result->num_ransac_iterations = iteration;
  return best;
}

}  // namespace

bool Sim3SolverOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Above("max_ransac_iterations", max_ransac_iterations, 0);
  check.InRange("confidence", confidence, 0.0, 1.0, Interval::kOpen);
  check.Above("chi_square_threshold", chi_square_threshold, 0.0);
  check.AtLeast("min_inliers", min_inliers, 3);
  check.AtLeast("refine_iterations", refine_iterations, 0);
  check.Above("huber_delta", huber_delta, 0.0);
  check.AtLeast("min_scale_baseline_ratio", min_scale_baseline_ratio, 0.0);
  check.Above("min_scale", min_scale, 0.0);
  check.AtLeast("max_scale", max_scale, min_scale, "min_scale");
  return check.ok();
}

Eigen::Vector2d Sim3ChiSquares(const CameraModel& current_camera,
                               const CameraModel& candidate_camera,
                               const Sim3Correspondence& correspondence,
                               const Sim3& candidate_from_current) {
  Eigen::Vector4d r;
  if (!WhitenedResiduals(current_camera, candidate_camera, correspondence, candidate_from_current,
                         candidate_from_current.Inverse(), &r)) {
    return Eigen::Vector2d(kInfinity, kInfinity);
  }
  return Eigen::Vector2d(r.head<2>().squaredNorm(), r.tail<2>().squaredNorm());
}

Sim3SolverResult SolveSim3(const CameraModel& current_camera, const CameraModel& candidate_camera,
                           const std::vector<Sim3Correspondence>& correspondences,
                           const Sim3SolverOptions& options) {
  Sim3SolverResult result;
  result.inliers.assign(correspondences.size(), false);
  if (!options.Check()) {
    result.message = "invalid options";
    return result;
  }
  if (static_cast<int>(correspondences.size()) < options.min_inliers) {
    result.message = "fewer correspondences than min_inliers";
    return result;
  }
  const std::optional<Sim3> best =
      Ransac(current_camera, candidate_camera, correspondences, options, &result);
  if (!best) {
    result.message = "no non-degenerate sample";
    return result;
  }
  // Least squares on the RANSAC inliers, then LM on their reprojection errors; the inliers
  // are classified again after each stage.
  InlierSet set = CountInliers(current_camera, candidate_camera, correspondences, *best,
                               options.chi_square_threshold);
  Sim3 model = *best;
  std::vector<std::size_t> inlier_indices;
  for (std::size_t i = 0; i < set.inliers.size(); ++i) {
    if (set.inliers[i]) inlier_indices.push_back(i);
  }
  if (const auto refit = FitSubset(correspondences, inlier_indices, options.fix_scale)) {
    const InlierSet refit_set = CountInliers(current_camera, candidate_camera, correspondences,
                                             *refit, options.chi_square_threshold);
    if (refit_set.count >= set.count) {
      model = *refit;
      set = refit_set;
    }
  }
  if (options.refine_iterations > 0) {
    const bool scale_observable =
        BaselineDepthRatio(correspondences, set.inliers, model) >= options.min_scale_baseline_ratio;
    RefineProblem problem{current_camera, candidate_camera, {}, options.huber_delta,
                          options.fix_scale || !scale_observable ? 6 : 7};
    for (std::size_t i = 0; i < correspondences.size(); ++i) {
      if (set.inliers[i]) problem.matches.push_back(&correspondences[i]);
    }
    model = Refine(problem, model, options.refine_iterations);
    set = CountInliers(current_camera, candidate_camera, correspondences, model,
                       options.chi_square_threshold);
  }
  result.candidate_from_current = model;
  result.inliers = set.inliers;
  result.num_inliers = set.count;
  result.inlier_rms_px =
      InlierRms(current_camera, candidate_camera, correspondences, set.inliers, model);
  if (!(model.scale >= options.min_scale && model.scale <= options.max_scale)) {
    result.message = "implausible scale " + std::to_string(model.scale);
    return result;
  }
  result.success = set.count >= options.min_inliers;
  if (!result.success) result.message = "too few inliers";
  return result;
}

}  // namespace arucoslam
