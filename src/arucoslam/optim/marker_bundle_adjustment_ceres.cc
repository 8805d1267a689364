// The Ceres side of SolveMarkerBundleAdjustment: poses and markers as [qx qy qz qw tx ty tz]
// blocks on a left SE(3) manifold, analytic keypoint and marker-corner costs.
#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "arucoslam/markers/marker_pose.h"
#include "arucoslam/optim/marker_bundle_adjustment.h"
#include "arucoslam/optim/reprojection_cost_ceres.h"
#include "arucoslam/optim/se3_manifold_ceres.h"
#include "arucoslam/optim/solve_ceres.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {
namespace {

using ceres_internal::kPoseSize;
using ceres_internal::PoseBlock;
using ceres_internal::ReprojectionCosts;
using ceres_internal::WritePoseJacobian;
using LeftSe3Manifold = ceres_internal::Se3LeftManifold;

Rigid3 FromBlock(const double* block) { return ceres_internal::PoseFromBlock(block); }
PoseBlock ToBlock(const Rigid3& pose) { return ceres_internal::PoseToBlock(pose); }

class MarkerCornerCost : public ceres::SizedCostFunction<8, kPoseSize, kPoseSize> {
 public:
  MarkerCornerCost(const MarkerCornerError& error, double sigma)
      : error_(error), inverse_sigma_(1.0 / sigma) {}
  bool Evaluate(const double* const* parameters, double* residuals,
                double** jacobians) const override {
    Vector8d residual = Vector8d::Zero();
    MarkerCornerJacobian d_cam = MarkerCornerJacobian::Zero();
    MarkerCornerJacobian d_marker = MarkerCornerJacobian::Zero();
    const bool want = jacobians != nullptr;
    if (!error_.Evaluate(FromBlock(parameters[0]), FromBlock(parameters[1]), &residual,
                         want ? &d_cam : nullptr, want ? &d_marker : nullptr)) {
      residual.setZero();
      d_cam.setZero();
      d_marker.setZero();
    }
    Eigen::Map<Vector8d> whitened(residuals);
    whitened = inverse_sigma_ * residual;
    if (want && jacobians[0] != nullptr) WritePoseJacobian<8>(d_cam, inverse_sigma_, jacobians[0]);
    if (want && jacobians[1] != nullptr) {
      WritePoseJacobian<8>(d_marker, inverse_sigma_, jacobians[1]);
    }
    return true;
  }

 private:
  MarkerCornerError error_;
  double inverse_sigma_;
};

class GroundPlaneCost : public ceres::SizedCostFunction<3, kPoseSize, 1, 3> {
 public:
  explicit GroundPlaneCost(const GroundPlanePriorOptions& options) : error_(options) {}
  bool Evaluate(const double* const* parameters, double* residuals,
                double** jacobians) const override {
    const GroundPlane plane{parameters[1][0], Eigen::Vector3d(parameters[2])};
    Eigen::Vector3d residual;
    GroundPlanePoseJacobian d_pose;
    GroundPlaneHeightJacobian d_height;
    GroundPlaneUpJacobian d_up;
    const bool want = jacobians != nullptr;
    error_.Evaluate(FromBlock(parameters[0]), plane, &residual, want ? &d_pose : nullptr,
                    want ? &d_height : nullptr, want ? &d_up : nullptr);
    Eigen::Map<Eigen::Vector3d> whitened(residuals);
    whitened = residual;
    if (want && jacobians[0] != nullptr) WritePoseJacobian<3>(d_pose, 1.0, jacobians[0]);
    if (want && jacobians[1] != nullptr) {
      Eigen::Map<Eigen::Vector3d> j(jacobians[1]);
      j = d_height;
    }
    if (want && jacobians[2] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> j(jacobians[2]);
      j = d_up;
    }
    return true;
  }

 private:
  GroundPlaneError error_;
};

class PositionPriorCost : public ceres::SizedCostFunction<3, kPoseSize> {
 public:
  explicit PositionPriorCost(const PositionPrior& prior) : error_(prior) {}
  bool Evaluate(const double* const* parameters, double* residuals,
                double** jacobians) const override {
    Eigen::Vector3d residual;
    PositionPriorPoseJacobian d_pose;
    const bool want = jacobians != nullptr && jacobians[0] != nullptr;
    error_.Evaluate(FromBlock(parameters[0]), &residual, want ? &d_pose : nullptr);
    Eigen::Map<Eigen::Vector3d> whitened(residuals);
    whitened = residual;
    if (want) WritePoseJacobian<3>(d_pose, 1.0, jacobians[0]);
    return true;
  }

 private:
  PositionPriorError error_;
};

// Ceres parameter blocks of a problem; `*_used` says which ones a residual touches.
struct Blocks {
  std::vector<PoseBlock> poses, markers;
  std::vector<std::array<double, 3>> points;
  std::vector<bool> pose_used, marker_used, point_used;
  double ground_height = 0.0;                // with a ground-plane prior
  std::array<double, 3> ground_up{0, 0, 0};  // unit, on a sphere manifold

  explicit Blocks(const MarkerBundleAdjustmentProblem& problem) {
    for (const auto& pose : problem.keypoints.poses) poses.push_back(ToBlock(pose.cam_from_world));
    for (const auto& marker : problem.markers) markers.push_back(ToBlock(marker.world_from_marker));
    for (const auto& point : problem.keypoints.points) {
      points.push_back({point.p_in_world.x(), point.p_in_world.y(), point.p_in_world.z()});
    }
    pose_used.assign(poses.size(), false);
    marker_used.assign(markers.size(), false);
    point_used.assign(points.size(), false);
  }

  void CopyTo(MarkerBundleAdjustmentProblem* problem) const {
    auto& keypoints = problem->keypoints;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (pose_used[i]) keypoints.poses[i].cam_from_world = FromBlock(poses[i].data());
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (point_used[i]) keypoints.points[i].p_in_world = Eigen::Vector3d(points[i].data());
    }
    for (std::size_t i = 0; i < markers.size(); ++i) {
      if (marker_used[i]) problem->markers[i].world_from_marker = FromBlock(markers[i].data());
    }
  }
};

// The cost functions of one solve (the ceres::Problem does not own them); outlive the problem.
struct Costs {
  ReprojectionCosts keypoints;
  std::vector<std::unique_ptr<ceres::CostFunction>> others;  // marker corners, priors

  explicit Costs(std::size_t num_keypoint_observations) : keypoints(num_keypoint_observations) {}
  template <typename Cost, typename... Args>
  Cost* AddOther(Args&&... args) {
    others.push_back(std::make_unique<Cost>(std::forward<Args>(args)...));
    return static_cast<Cost*>(others.back().get());
  }
};

// Marks a block used on first sight: manifold, constancy.
void Use(double* block, bool fixed, ceres::Manifold* manifold, std::vector<bool>::reference used,
         ceres::Problem* ceres_problem) {
  if (used) return;
  used = true;
  if (manifold != nullptr) ceres_problem->SetManifold(block, manifold);
  if (fixed) ceres_problem->SetParameterBlockConstant(block);
}

void AddResiduals(const MarkerBundleAdjustmentProblem& problem, ceres::Manifold* manifold,
                  ceres::LossFunction* keypoint_loss, ceres::LossFunction* marker_loss,
                  Costs* costs, Blocks* blocks, ceres::Problem* ceres_problem) {
  const auto& keypoints = problem.keypoints;
  for (const auto& observation : keypoints.observations) {
    double* pose = blocks->poses[observation.pose_index].data();
    double* point = blocks->points[observation.point_index].data();
    ceres_problem->AddResidualBlock(
        costs->keypoints.Add(keypoints.intrinsics, observation.pixel, observation.sigma_px),
        keypoint_loss, pose, point);
    Use(pose, keypoints.poses[observation.pose_index].fixed, manifold,
        blocks->pose_used[observation.pose_index], ceres_problem);
    Use(point, keypoints.points[observation.point_index].fixed, nullptr,
        blocks->point_used[observation.point_index], ceres_problem);
  }
  for (const auto& observation : problem.marker_observations) {
    const auto& marker = problem.markers[observation.marker_index];
    double* pose = blocks->poses[observation.pose_index].data();
    double* marker_block = blocks->markers[observation.marker_index].data();
    const MarkerCornerError error(keypoints.intrinsics, SquareCorners(marker.size),
                                  observation.corners_px);
    ceres_problem->AddResidualBlock(costs->AddOther<MarkerCornerCost>(error, observation.sigma_px),
                                    marker_loss, pose, marker_block);
    Use(pose, keypoints.poses[observation.pose_index].fixed, manifold,
        blocks->pose_used[observation.pose_index], ceres_problem);
    Use(marker_block, marker.fixed, manifold, blocks->marker_used[observation.marker_index],
        ceres_problem);
  }
  // Only on poses an observation ties to the rest: a prior alone would just be met.
  for (const PositionPrior& prior : problem.position_priors) {
    if (!blocks->pose_used[prior.pose_index]) continue;
    ceres_problem->AddResidualBlock(costs->AddOther<PositionPriorCost>(prior), nullptr,
                                    blocks->poses[prior.pose_index].data());
  }
}

// The ground-plane prior on every pose a residual uses, the plane starting from their mean.
// False (nothing added) when no pose is used.
bool AddGroundPlanePrior(const GroundPlanePriorOptions& options, ceres::Manifold* sphere,
                         Costs* costs, Blocks* blocks, ceres::Problem* ceres_problem) {
  std::vector<Rigid3> poses;
  for (std::size_t i = 0; i < blocks->poses.size(); ++i) {
    if (blocks->pose_used[i]) poses.push_back(FromBlock(blocks->poses[i].data()));
  }
  if (poses.empty()) return false;
  const GroundPlane start = MeanGroundPlane(poses);
  blocks->ground_height = start.height_m;
  blocks->ground_up = {start.up_in_camera.x(), start.up_in_camera.y(), start.up_in_camera.z()};
  for (std::size_t i = 0; i < blocks->poses.size(); ++i) {
    if (!blocks->pose_used[i]) continue;
    ceres_problem->AddResidualBlock(costs->AddOther<GroundPlaneCost>(options), nullptr,
                                    blocks->poses[i].data(), &blocks->ground_height,
                                    blocks->ground_up.data());
  }
  ceres_problem->SetManifold(blocks->ground_up.data(), sphere);
  return true;
}

void FlagOutliers(const MarkerBundleAdjustmentOptions& options,
                  const MarkerBundleAdjustmentProblem& problem,
                  MarkerBundleAdjustmentSummary* summary) {
  const auto& keypoints = problem.keypoints;
  summary->keypoint_outliers = FlagReprojectionOutliers(
      keypoints, options.solver.chi_square_threshold, &summary->num_keypoint_outliers);
  summary->marker_outliers.assign(problem.marker_observations.size(), false);
  for (std::size_t i = 0; i < problem.marker_observations.size(); ++i) {
    const auto& observation = problem.marker_observations[i];
    const auto& marker = problem.markers[observation.marker_index];
    Vector8d residual;
    const bool in_front =
        MarkerCornerError(keypoints.intrinsics, SquareCorners(marker.size), observation.corners_px)
            .Evaluate(keypoints.poses[observation.pose_index].cam_from_world,
                      marker.world_from_marker, &residual);
    const double chi2 = residual.squaredNorm() / (observation.sigma_px * observation.sigma_px);
    summary->marker_outliers[i] = !in_front || chi2 > options.marker_chi_square_threshold;
    summary->num_marker_outliers += summary->marker_outliers[i] ? 1 : 0;
  }
}

}  // namespace

MarkerBundleAdjustmentSummary SolveMarkerBundleAdjustment(
    const MarkerBundleAdjustmentOptions& options, MarkerBundleAdjustmentProblem* problem) {
  MarkerBundleAdjustmentSummary summary;
  if (!ceres_internal::InputsCheckOut(options, *problem, &summary)) return summary;
  const Stopwatch stopwatch;
  summary.initial_keypoint_rms_px = ReprojectionRmsPixels(problem->keypoints);
  summary.initial_marker_rms_px = MarkerReprojectionRmsPixels(*problem);

  Blocks blocks(*problem);
  Costs costs(problem->keypoints.observations.size());
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  LeftSe3Manifold manifold;
  ceres::HuberLoss keypoint_loss(options.solver.huber_delta_px);
  ceres::HuberLoss marker_loss(options.marker_huber_delta);
  AddResiduals(*problem, &manifold, &keypoint_loss, &marker_loss, &costs, &blocks, &ceres_problem);
  ceres::SphereManifold<3> sphere;
  const bool ground_plane =
      problem->ground_plane_prior &&
      AddGroundPlanePrior(*problem->ground_plane_prior, &sphere, &costs, &blocks, &ceres_problem);
  if (ceres_internal::NothingToSolve(ceres_problem, "no observations", &summary)) return summary;

  // Points eliminated first; poses and markers form the reduced camera system.
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (std::size_t i = 0; i < blocks.points.size(); ++i) {
    if (blocks.point_used[i]) ordering->AddElementToGroup(blocks.points[i].data(), 0);
  }
  for (std::size_t i = 0; i < blocks.poses.size(); ++i) {
    if (blocks.pose_used[i]) ordering->AddElementToGroup(blocks.poses[i].data(), 1);
  }
  for (std::size_t i = 0; i < blocks.markers.size(); ++i) {
    if (blocks.marker_used[i]) ordering->AddElementToGroup(blocks.markers[i].data(), 1);
  }
  if (ground_plane) {
    ordering->AddElementToGroup(&blocks.ground_height, 1);
    ordering->AddElementToGroup(blocks.ground_up.data(), 1);
  }
  const bool has_points = ordering->NumElements() > 0 && ordering->GroupSize(0) > 0;
  ceres_internal::SolveOptions solve_options =
      ceres_internal::BundleAdjustmentSolveOptions(options.solver);
  // Without points: dense QR for a handful of blocks (one new marker), else the sparse
  // normal equations (many marker views: dense QR grows with views^3).
  constexpr int kMaxDenseBlocks = 16;
  solve_options.linear_solver_type =
      has_points ? ceres::DENSE_SCHUR
      : ceres_problem.NumParameterBlocks() <= kMaxDenseBlocks ? ceres::DENSE_QR
                                                               : ceres::SPARSE_NORMAL_CHOLESKY;
  if (has_points) solve_options.ordering = ordering;
  ceres_internal::Solve(solve_options, &ceres_problem, &summary);
  if (summary.success) blocks.CopyTo(problem);
  if (summary.success && ground_plane) {
    summary.ground_plane =
        GroundPlane{blocks.ground_height, Eigen::Vector3d(blocks.ground_up.data())};
  }
  summary.final_keypoint_rms_px = ReprojectionRmsPixels(problem->keypoints);
  summary.final_marker_rms_px = MarkerReprojectionRmsPixels(*problem);
  for (const PositionPrior& prior : problem->position_priors) {
    if (!blocks.pose_used[prior.pose_index]) continue;
    Eigen::Vector3d residual;
    PositionPriorError(prior).Evaluate(problem->keypoints.poses[prior.pose_index].cam_from_world,
                                       &residual);
    ++summary.num_position_priors;
    summary.max_position_prior_sigmas =
        std::max(summary.max_position_prior_sigmas, residual.norm());
  }
  FlagOutliers(options, *problem, &summary);
  summary.solve_seconds = stopwatch.ElapsedSeconds();
  return summary;
}

}  // namespace arucoslam
