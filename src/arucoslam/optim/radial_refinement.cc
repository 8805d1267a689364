#include "arucoslam/optim/radial_refinement.h"

#include <ceres/ceres.h>

#include <array>
#include <vector>

#include "arucoslam/optim/radial_reprojection_cost_ceres.h"
#include "arucoslam/optim/se3_manifold_ceres.h"
#include "arucoslam/optim/solve_ceres.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {
namespace {

using ceres_internal::kPoseSize;
using ceres_internal::PoseFromBlock;
using ceres_internal::RadialReprojectionCost;

}  // namespace

RadialRefinementSummary SolveBundleAdjustmentWithRadialTerm(const BundleAdjustmentOptions& options,
                                                            BundleAdjustmentProblem* problem) {
  RadialRefinementSummary result;
  BundleAdjustmentSummary& summary = result.solve;
  if (!ceres_internal::InputsCheckOut(options, *problem, &summary)) return result;
  const Stopwatch stopwatch;
  summary.initial_rms_px = ReprojectionRmsPixels(*problem);
  std::vector<std::array<double, kPoseSize>> poses(problem->poses.size());
  std::vector<std::array<double, 3>> points(problem->points.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    ceres_internal::PoseToBlock(problem->poses[i].cam_from_world, poses[i].data());
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    Eigen::Map<Eigen::Vector3d>(points[i].data()) = problem->points[i].p_in_world;
  }
  double k = 0.0;
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  ceres_internal::Se3LeftManifold manifold;
  ceres::HuberLoss loss(options.huber_delta_px);
  std::vector<bool> pose_used(poses.size(), false), point_used(points.size(), false);
  for (const auto& observation : problem->observations) {
    double* pose = poses[observation.pose_index].data();
    double* point = points[observation.point_index].data();
    ceres_problem.AddResidualBlock(
        new RadialReprojectionCost(problem->intrinsics, observation.pixel, observation.sigma_px),
        &loss, pose, point, &k);
    if (!pose_used[observation.pose_index]) {
      pose_used[observation.pose_index] = true;
      ceres_problem.SetManifold(pose, &manifold);
      if (problem->poses[observation.pose_index].fixed) ceres_problem.SetParameterBlockConstant(pose);
    }
    if (!point_used[observation.point_index]) {
      point_used[observation.point_index] = true;
      if (problem->points[observation.point_index].fixed) {
        ceres_problem.SetParameterBlockConstant(point);
      }
    }
  }
  if (ceres_internal::NothingToSolve(ceres_problem, "no observations", &summary)) return result;
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (point_used[i]) ordering->AddElementToGroup(points[i].data(), 0);
  }
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (pose_used[i]) ordering->AddElementToGroup(poses[i].data(), 1);
  }
  ordering->AddElementToGroup(&k, 1);
  ceres_internal::SolveOptions solve_options = ceres_internal::BundleAdjustmentSolveOptions(options);
  solve_options.linear_solver_type = ceres::DENSE_SCHUR;
  solve_options.ordering = ordering;
  ceres_internal::Solve(solve_options, &ceres_problem, &summary);
  if (summary.success) {
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (pose_used[i]) problem->poses[i].cam_from_world = PoseFromBlock(poses[i].data());
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (point_used[i]) {
        problem->points[i].p_in_world = Eigen::Map<const Eigen::Vector3d>(points[i].data());
      }
    }
    result.k = k;
  }
  summary.final_rms_px = ReprojectionRmsPixels(*problem);
  summary.solve_seconds = stopwatch.ElapsedSeconds();
  return result;
}

std::optional<CameraModel> WithRadialTerm(const CameraModel& camera, double k) {
  if (camera.model == DistortionModel::kEquidistant) return std::nullopt;
  CameraModel corrected = camera;
  if (corrected.model == DistortionModel::kNone) corrected.model = DistortionModel::kRadTan;
  corrected.distortion[0] += k;
  return corrected;
}

}  // namespace arucoslam
