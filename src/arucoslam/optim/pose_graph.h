// Sim3 pose graph: keyframe poses (cam_from_world similarities) linked by relative-pose
// measurements and absolute priors, as a solver-free problem; SolvePoseGraph runs Ceres.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/geometry/sim3.h"

namespace arucoslam {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix7d = Eigen::Matrix<double, 7, 7>;

struct PoseGraphOptions {
  // Maximum Levenberg-Marquardt iterations.
  int max_iterations = 20;
  // Relative decrease of the cost below which the solver stops.
  double function_tolerance = 1e-10;
  // Metric map (markers): every node keeps its scale (an SE(3) graph); the sigma rows of the
  // relative residuals still penalise scale disagreement of the measurements.
  bool fix_scale = false;
  int num_threads = 1;  // solver threads

  bool Check(std::string* why = nullptr) const;
};

struct PoseGraphProblem {
  struct Node {
    Sim3 cam_from_world;
    bool fixed = false;  // held constant (the loop keyframe; gauge)
  };
  // Relative measurement between nodes `from` (i) and `to` (j): j_from_i = S_j * S_i^-1.
  // Residual: Log(to_from_from * S_i * S_j^-1) in the Sim3 tangent [upsilon; omega; sigma],
  // whitened by `information` (inverse covariance of that tangent).
  struct Edge {
    std::size_t from = 0;
    std::size_t to = 0;
    Sim3 to_from_from;
    Matrix7d information = Matrix7d::Identity();
  };
  // Absolute pose measurement of node `node`. Residual: [camera centre - measured centre,
  // world frame, metres; Log(R_measured^-1 * R_world_from_cam), radians], whitened by
  // `information` (6x6 inverse covariance of that vector).
  struct PosePrior {
    std::size_t node = 0;
    Rigid3 world_from_cam;
    Matrix6d information = Matrix6d::Identity();
  };

  std::vector<Node> nodes;
  std::vector<Edge> edges;
  std::vector<PosePrior> priors;

  // Indices valid, from != to, positive scales, information symmetric positive definite.
  bool Check(std::string* reason = nullptr) const;
};

struct PoseGraphSummary {
  bool success = false;
  int num_iterations = 0;
  int num_residual_blocks = 0;
  double initial_cost = 0.0;  // half the sum of squared whitened residuals
  double final_cost = 0.0;
  double solve_seconds = 0.0;
  std::string message;

  std::string BriefReport() const;
};

// Solves in place (all nodes but the fixed ones). Without a fixed node or a prior the gauge
// is free: fix at least one node.
PoseGraphSummary SolvePoseGraph(const PoseGraphOptions& options, PoseGraphProblem* problem);

// Sum of squared whitened residuals (edges and priors) of the current estimate.
double PoseGraphChiSquare(const PoseGraphProblem& problem);

}  // namespace arucoslam
