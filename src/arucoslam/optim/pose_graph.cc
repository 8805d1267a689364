#include "arucoslam/optim/pose_graph.h"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <cmath>

#include "arucoslam/optim/pose_graph_residuals.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

template <int N>
bool IsInformation(const Eigen::Matrix<double, N, N>& information) {
  if (!information.allFinite()) return false;
  if ((information - information.transpose()).cwiseAbs().maxCoeff() >
      1e-9 * std::max(1.0, information.cwiseAbs().maxCoeff())) {
    return false;
  }
  return Eigen::LLT<Eigen::Matrix<double, N, N>>(information).info() == Eigen::Success;
}

pose_graph_internal::SimilarityT<double> ToSimilarity(const Sim3& s) {
  return {s.scale, s.rotation, s.translation};
}

}  // namespace

bool PoseGraphOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Above("max_iterations", max_iterations, 0);
  check.Above("function_tolerance", function_tolerance, 0.0);
  check.Above("num_threads", num_threads, 0);
  return check.ok();
}

bool PoseGraphProblem::Check(std::string* reason) const {
  auto fail = [&](const std::string& message) {
    if (reason != nullptr) *reason = message;
    return false;
  };
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (!(nodes[i].cam_from_world.scale > 0.0) ||
        !nodes[i].cam_from_world.translation.allFinite()) {
      return fail(fmt::format("node {} has a non-positive scale or a non-finite pose", i));
    }
  }
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const Edge& edge = edges[k];
    if (edge.from >= nodes.size() || edge.to >= nodes.size() || edge.from == edge.to) {
      return fail(fmt::format("edge {} has invalid node indices", k));
    }
    if (!(edge.to_from_from.scale > 0.0) || !IsInformation<7>(edge.information)) {
      return fail(fmt::format("edge {} has a bad scale or information matrix", k));
    }
  }
  for (std::size_t k = 0; k < priors.size(); ++k) {
    if (priors[k].node >= nodes.size() || !IsInformation<6>(priors[k].information)) {
      return fail(fmt::format("prior {} has an invalid node or information matrix", k));
    }
  }
  return true;
}

std::string PoseGraphSummary::BriefReport() const {
  return fmt::format(
      "pose graph: {} residuals, {} iterations, cost {:.4g} -> {:.4g}, {:.1f} ms ({})",
      num_residual_blocks, num_iterations, initial_cost, final_cost, 1e3 * solve_seconds, message);
}

double PoseGraphChiSquare(const PoseGraphProblem& problem) {
  using pose_graph_internal::PosePriorError;
  using pose_graph_internal::RelativeSimilarityError;
  double sum = 0.0;
  for (const auto& edge : problem.edges) {
    const Vector7d error = RelativeSimilarityError(
        ToSimilarity(edge.to_from_from), ToSimilarity(problem.nodes[edge.from].cam_from_world),
        ToSimilarity(problem.nodes[edge.to].cam_from_world));
    sum += error.dot(edge.information * error);
  }
  for (const auto& prior : problem.priors) {
    const Vector6d error =
        PosePriorError(prior.world_from_cam.rotation, prior.world_from_cam.translation,
                       ToSimilarity(problem.nodes[prior.node].cam_from_world));
    sum += error.dot(prior.information * error);
  }
  return sum;
}

}  // namespace arucoslam
