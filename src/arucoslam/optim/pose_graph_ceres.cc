// The Ceres side of SolvePoseGraph: each node is a unit quaternion (4), a translation (3) and
// a log-scale (1); residuals are differentiated automatically (pose_graph_residuals.h).
#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <array>
#include <cmath>
#include <vector>

#include "arucoslam/optim/pose_graph.h"
#include "arucoslam/optim/pose_graph_residuals.h"
#include "arucoslam/optim/solve_ceres.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {
namespace {

using pose_graph_internal::SimilarityT;

template <typename T>
SimilarityT<T> NodeFromBlocks(const T* rotation, const T* translation, const T* log_scale) {
  using std::exp;
  return {exp(log_scale[0]),
          Eigen::Quaternion<T>(rotation[3], rotation[0], rotation[1], rotation[2]),
          Eigen::Matrix<T, 3, 1>(translation[0], translation[1], translation[2])};
}

template <int N>
Eigen::Matrix<double, N, N> SquareRootInformation(const Eigen::Matrix<double, N, N>& information) {
  // information = U^T U; whitened residual U * e has squared norm e^T information e.
  return Eigen::LLT<Eigen::Matrix<double, N, N>>(information).matrixU();
}

struct RelativeCost {
  Sim3 to_from_from;
  Matrix7d sqrt_information;

  template <typename T>
  bool operator()(const T* rotation_i, const T* translation_i, const T* log_scale_i,
                  const T* rotation_j, const T* translation_j, const T* log_scale_j,
                  T* residual) const {
    const SimilarityT<T> measured{T(to_from_from.scale), to_from_from.rotation.cast<T>(),
                                  to_from_from.translation.cast<T>()};
    const Eigen::Matrix<T, 7, 1> error = pose_graph_internal::RelativeSimilarityError(
        measured, NodeFromBlocks(rotation_i, translation_i, log_scale_i),
        NodeFromBlocks(rotation_j, translation_j, log_scale_j));
    Eigen::Map<Eigen::Matrix<T, 7, 1>> whitened(residual);
    whitened = sqrt_information.cast<T>() * error;
    return true;
  }
};

struct PriorCost {
  Rigid3 world_from_cam;
  Matrix6d sqrt_information;

  template <typename T>
  bool operator()(const T* rotation, const T* translation, const T* log_scale, T* residual) const {
    const Eigen::Matrix<T, 6, 1> error = pose_graph_internal::PosePriorError(
        Eigen::Quaternion<T>(world_from_cam.rotation.cast<T>()),
        Eigen::Matrix<T, 3, 1>(world_from_cam.translation.cast<T>()),
        NodeFromBlocks(rotation, translation, log_scale));
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residual);
    whitened = sqrt_information.cast<T>() * error;
    return true;
  }
};

struct NodeBlocks {
  std::array<double, 4> rotation;  // x y z w
  std::array<double, 3> translation;
  std::array<double, 1> log_scale;
  bool used = false;
};

std::vector<NodeBlocks> MakeBlocks(const PoseGraphProblem& problem) {
  std::vector<NodeBlocks> blocks(problem.nodes.size());
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const Sim3& s = problem.nodes[i].cam_from_world;
    const Eigen::Quaterniond q = s.rotation.normalized();
    blocks[i].rotation = {q.x(), q.y(), q.z(), q.w()};
    blocks[i].translation = {s.translation.x(), s.translation.y(), s.translation.z()};
    blocks[i].log_scale = {std::log(s.scale)};
  }
  return blocks;
}

void ConfigureNode(const PoseGraphOptions& options, const PoseGraphProblem::Node& node,
                   ceres::Manifold* quaternion_manifold, NodeBlocks* blocks,
                   ceres::Problem* ceres_problem) {
  if (blocks->used) return;
  blocks->used = true;
  ceres_problem->SetManifold(blocks->rotation.data(), quaternion_manifold);
  if (node.fixed) {
    ceres_problem->SetParameterBlockConstant(blocks->rotation.data());
    ceres_problem->SetParameterBlockConstant(blocks->translation.data());
  }
  if (node.fixed || options.fix_scale) {
    ceres_problem->SetParameterBlockConstant(blocks->log_scale.data());
  }
}

void AddResiduals(const PoseGraphOptions& options, const PoseGraphProblem& problem,
                  ceres::Manifold* quaternion_manifold, std::vector<NodeBlocks>* blocks,
                  ceres::Problem* ceres_problem) {
  for (const auto& edge : problem.edges) {
    NodeBlocks& i = (*blocks)[edge.from];
    NodeBlocks& j = (*blocks)[edge.to];
    auto* cost = new ceres::AutoDiffCostFunction<RelativeCost, 7, 4, 3, 1, 4, 3, 1>(
        new RelativeCost{edge.to_from_from, SquareRootInformation<7>(edge.information)});
    ceres_problem->AddResidualBlock(cost, nullptr, i.rotation.data(), i.translation.data(),
                                    i.log_scale.data(), j.rotation.data(), j.translation.data(),
                                    j.log_scale.data());
    ConfigureNode(options, problem.nodes[edge.from], quaternion_manifold, &i, ceres_problem);
    ConfigureNode(options, problem.nodes[edge.to], quaternion_manifold, &j, ceres_problem);
  }
  for (const auto& prior : problem.priors) {
    NodeBlocks& node = (*blocks)[prior.node];
    auto* cost = new ceres::AutoDiffCostFunction<PriorCost, 6, 4, 3, 1>(
        new PriorCost{prior.world_from_cam, SquareRootInformation<6>(prior.information)});
    ceres_problem->AddResidualBlock(cost, nullptr, node.rotation.data(), node.translation.data(),
                                    node.log_scale.data());
    ConfigureNode(options, problem.nodes[prior.node], quaternion_manifold, &node, ceres_problem);
  }
}

}  // namespace

PoseGraphSummary SolvePoseGraph(const PoseGraphOptions& options, PoseGraphProblem* problem) {
  PoseGraphSummary summary;
  if (!ceres_internal::InputsCheckOut(options, *problem, &summary)) return summary;
  const Stopwatch stopwatch;
  std::vector<NodeBlocks> blocks = MakeBlocks(*problem);
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  ceres::EigenQuaternionManifold quaternion_manifold;
  AddResiduals(options, *problem, &quaternion_manifold, &blocks, &ceres_problem);
  if (ceres_internal::NothingToSolve(ceres_problem, "no edges or priors", &summary)) {
    return summary;
  }
  ceres_internal::SolveOptions solve_options;
  solve_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solve_options.max_iterations = options.max_iterations;
  solve_options.function_tolerance = options.function_tolerance;
  solve_options.num_threads = options.num_threads;
  ceres_internal::Solve(solve_options, &ceres_problem, &summary);
  if (summary.success) {
    for (std::size_t n = 0; n < blocks.size(); ++n) {
      if (!blocks[n].used || problem->nodes[n].fixed) continue;
      const NodeBlocks& b = blocks[n];
      problem->nodes[n].cam_from_world =
          Sim3(std::exp(b.log_scale[0]),
               Eigen::Quaterniond(b.rotation[3], b.rotation[0], b.rotation[1], b.rotation[2]),
               Eigen::Vector3d(b.translation[0], b.translation[1], b.translation[2]));
    }
  }
  summary.solve_seconds = stopwatch.ElapsedSeconds();
  return summary;
}

}  // namespace arucoslam
