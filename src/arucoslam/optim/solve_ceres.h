// Internal to optim/'s *_ceres.cc files: the one place a Ceres solve is configured and run
// (silent, with an optional stop request), its outcome copied into an optim/ summary.
#pragma once

#include <ceres/ceres.h>

#include <functional>
#include <memory>
#include <string>

#include "arucoslam/optim/bundle_adjustment.h"

namespace arucoslam::ceres_internal {

// What differs between the optimisers' solves; everything else is Ceres' default.
struct SolveOptions {
  ceres::LinearSolverType linear_solver_type = ceres::DENSE_SCHUR;
  // Elimination order for the Schur solvers; null lets Ceres choose.
  std::shared_ptr<ceres::ParameterBlockOrdering> ordering;
  int max_iterations = 20;           // Levenberg-Marquardt steps
  double function_tolerance = 1e-6;  // relative cost decrease that ends the solve
  int num_threads = 1;               // solver threads
  // Asked after each iteration from min_iterations_before_stop on: true ends the solve
  // there with the best iterate so far (Ceres reports USER_SUCCESS). Empty: never asked.
  std::function<bool()> stop_requested;
  int min_iterations_before_stop = 1;
};

// Before a solve: false, with the reason in summary->message, when `options` or `problem`
// (optim/ types with Check) do not check out.
template <typename Options, typename Problem, typename Summary>
bool InputsCheckOut(const Options& options, const Problem& problem, Summary* summary) {
  std::string reason;
  if (!options.Check()) {
    summary->message = "invalid options";
    return false;
  }
  if (!problem.Check(&reason)) {
    summary->message = reason;
    return false;
  }
  return true;
}

// After the residuals are added: records their number in `summary` and, when there are none,
// marks it a success with `message` and returns true (nothing to solve).
template <typename Summary>
bool NothingToSolve(const ceres::Problem& problem, const char* message, Summary* summary) {
  summary->num_residual_blocks = problem.NumResidualBlocks();
  if (summary->num_residual_blocks != 0) return false;
  summary->success = true;
  summary->message = message;
  return true;
}

// The solver settings of BundleAdjustmentOptions (iterations, tolerance, threads, stop
// request) with `linear_solver_type` and `ordering` left at their defaults.
SolveOptions BundleAdjustmentSolveOptions(const BundleAdjustmentOptions& options);

// Solves `problem` with `options`, logging silenced.
ceres::Solver::Summary Solve(const SolveOptions& options, ceres::Problem* problem);

// Solve, then what every optim/ summary reports of it (success, iterations, costs, message)
// copied into `summary`, and stopped_early where its type has that field.
template <typename Summary>
void Solve(const SolveOptions& options, ceres::Problem* problem, Summary* summary) {
  const ceres::Solver::Summary ceres_summary = Solve(options, problem);
  summary->success = ceres_summary.IsSolutionUsable();
  summary->num_iterations = static_cast<int>(ceres_summary.iterations.size()) - 1;
  summary->initial_cost = ceres_summary.initial_cost;
  summary->final_cost = ceres_summary.final_cost;
  summary->message = ceres_summary.message;
  if constexpr (requires { summary->stopped_early; }) {
    summary->stopped_early = ceres_summary.termination_type == ceres::USER_SUCCESS;
  }
}

}  // namespace arucoslam::ceres_internal
