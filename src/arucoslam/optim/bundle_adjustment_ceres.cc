// The Ceres side of SolveBundleAdjustment and SolveBundleAdjustmentWithRadialTerm: an SE(3)
// manifold for poses stored as [qx qy qz qw tx ty tz] and analytic reprojection costs
// (ReprojectionError, with or without the shared radial coefficient).
#include <ceres/ceres.h>

#include <array>
#include <memory>
#include <vector>

#include "arucoslam/optim/bundle_adjustment.h"
#include "arucoslam/optim/radial_refinement.h"
#include "arucoslam/optim/radial_reprojection_cost_ceres.h"
#include "arucoslam/optim/reprojection_cost_ceres.h"
#include "arucoslam/optim/se3_manifold_ceres.h"
#include "arucoslam/optim/solve_ceres.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {
namespace {

using ceres_internal::kPoseSize;
using ceres_internal::PoseFromBlock;
using ceres_internal::PoseToBlock;
using ceres_internal::RadialReprojectionCost;
using ceres_internal::ReprojectionCosts;
using ceres_internal::Se3LeftManifold;

// Parameter blocks of a problem in Ceres' layout and which of them observations use.
struct CeresBlocks {
  std::vector<std::array<double, kPoseSize>> poses;
  std::vector<std::array<double, 3>> points;
  std::vector<bool> pose_used;
  std::vector<bool> point_used;

  explicit CeresBlocks(const BundleAdjustmentProblem& problem)
      : poses(problem.poses.size()),
        points(problem.points.size()),
        pose_used(problem.poses.size(), false),
        point_used(problem.points.size(), false) {
    for (std::size_t i = 0; i < poses.size(); ++i) {
      PoseToBlock(problem.poses[i].cam_from_world, poses[i].data());
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
      Eigen::Map<Eigen::Vector3d>(points[i].data()) = problem.points[i].p_in_world;
    }
  }

  void CopyTo(BundleAdjustmentProblem* problem) const {
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (pose_used[i]) problem->poses[i].cam_from_world = PoseFromBlock(poses[i].data());
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (point_used[i]) {
        problem->points[i].p_in_world = Eigen::Map<const Eigen::Vector3d>(points[i].data());
      }
    }
  }

  // Points first in the Schur elimination order, then poses (and `radial_k` with them).
  std::shared_ptr<ceres::ParameterBlockOrdering> SchurOrdering(double* radial_k) {
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (point_used[i]) ordering->AddElementToGroup(points[i].data(), 0);
    }
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (pose_used[i]) ordering->AddElementToGroup(poses[i].data(), 1);
    }
    if (radial_k != nullptr) ordering->AddElementToGroup(radial_k, 1);
    return ordering;
  }
};

// One residual block per observation; manifold and constancy set once per block. With
// `radial_k` every block also takes that shared coefficient (its costs kept in `radial_costs`).
void AddResiduals(const BundleAdjustmentProblem& problem, ceres::Manifold* manifold,
                  ceres::LossFunction* loss, ReprojectionCosts* costs, double* radial_k,
                  std::vector<std::unique_ptr<RadialReprojectionCost>>* radial_costs,
                  CeresBlocks* blocks, ceres::Problem* ceres_problem) {
  for (const auto& observation : problem.observations) {
    double* pose_block = blocks->poses[observation.pose_index].data();
    double* point_block = blocks->points[observation.point_index].data();
    if (radial_k == nullptr) {
      ceres_problem->AddResidualBlock(
          costs->Add(problem.intrinsics, observation.pixel, observation.sigma_px), loss,
          pose_block, point_block);
    } else {
      radial_costs->push_back(std::make_unique<RadialReprojectionCost>(
          problem.intrinsics, observation.pixel, observation.sigma_px));
      ceres_problem->AddResidualBlock(radial_costs->back().get(), loss, pose_block, point_block,
                                      radial_k);
    }
    if (!blocks->pose_used[observation.pose_index]) {
      blocks->pose_used[observation.pose_index] = true;
      ceres_problem->SetManifold(pose_block, manifold);
      if (problem.poses[observation.pose_index].fixed) {
        ceres_problem->SetParameterBlockConstant(pose_block);
      }
    }
    if (!blocks->point_used[observation.point_index]) {
      blocks->point_used[observation.point_index] = true;
      if (problem.points[observation.point_index].fixed) {
        ceres_problem->SetParameterBlockConstant(point_block);
      }
    }
  }
}

// The solve of both entry points; `radial_k` (null: none) is estimated in place.
BundleAdjustmentSummary Solve(const BundleAdjustmentOptions& options,
                              BundleAdjustmentProblem* problem, double* radial_k) {
  BundleAdjustmentSummary summary;
  if (!ceres_internal::InputsCheckOut(options, *problem, &summary)) return summary;
  const Stopwatch stopwatch;
  summary.initial_rms_px = ReprojectionRmsPixels(*problem);

  CeresBlocks blocks(*problem);
  ReprojectionCosts costs(radial_k == nullptr ? problem->observations.size() : 0);
  std::vector<std::unique_ptr<RadialReprojectionCost>> radial_costs;
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  Se3LeftManifold manifold;
  ceres::HuberLoss loss(options.huber_delta_px);
  AddResiduals(*problem, &manifold, &loss, &costs, radial_k, &radial_costs, &blocks,
               &ceres_problem);
  if (ceres_internal::NothingToSolve(ceres_problem, "no observations", &summary)) return summary;

  ceres_internal::SolveOptions solve_options =
      ceres_internal::BundleAdjustmentSolveOptions(options);
  solve_options.linear_solver_type = ceres::DENSE_SCHUR;
  solve_options.ordering = blocks.SchurOrdering(radial_k);
  ceres_internal::Solve(solve_options, &ceres_problem, &summary);
  if (summary.success) blocks.CopyTo(problem);
  summary.final_rms_px = ReprojectionRmsPixels(*problem);
  summary.outliers =
      FlagReprojectionOutliers(*problem, options.chi_square_threshold, &summary.num_outliers);
  summary.solve_seconds = stopwatch.ElapsedSeconds();
  return summary;
}

}  // namespace

BundleAdjustmentSummary SolveBundleAdjustment(const BundleAdjustmentOptions& options,
                                              BundleAdjustmentProblem* problem) {
  return Solve(options, problem, nullptr);
}

RadialRefinementSummary SolveBundleAdjustmentWithRadialTerm(const BundleAdjustmentOptions& options,
                                                            BundleAdjustmentProblem* problem) {
  RadialRefinementSummary result;
  double k = 0.0;
  result.solve = Solve(options, problem, &k);
  if (result.solve.success) result.k = k;
  return result;
}

}  // namespace arucoslam
