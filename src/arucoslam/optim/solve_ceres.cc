#include "arucoslam/optim/solve_ceres.h"

#include <utility>

namespace arucoslam::ceres_internal {
namespace {

// Ends a solve after an iteration once `stop_requested` says so (from iteration
// `min_iteration` on): Ceres keeps the best iterate reached and reports USER_SUCCESS.
class StopRequestCallback : public ceres::IterationCallback {
 public:
  StopRequestCallback(std::function<bool()> stop_requested, int min_iteration)
      : stop_requested_(std::move(stop_requested)), min_iteration_(min_iteration) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& iteration) override {
    if (iteration.iteration >= min_iteration_ && stop_requested_()) {
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }

 private:
  std::function<bool()> stop_requested_;
  int min_iteration_;
};

}  // namespace

SolveOptions BundleAdjustmentSolveOptions(const BundleAdjustmentOptions& options) {
  SolveOptions solve_options;
  solve_options.max_iterations = options.max_iterations;
  solve_options.function_tolerance = options.function_tolerance;
  solve_options.num_threads = options.num_threads;
  solve_options.stop_requested = options.stop_requested;
  solve_options.min_iterations_before_stop = options.min_iterations_before_stop;
  return solve_options;
}

ceres::Solver::Summary Solve(const SolveOptions& options, ceres::Problem* problem) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = options.linear_solver_type;
  if (options.ordering) solver_options.linear_solver_ordering = options.ordering;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.num_threads = options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  StopRequestCallback stop(options.stop_requested, options.min_iterations_before_stop);
  if (options.stop_requested) solver_options.callbacks.push_back(&stop);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, problem, &summary);
  return summary;
}

}  // namespace arucoslam::ceres_internal
