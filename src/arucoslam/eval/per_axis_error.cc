#include "arucoslam/eval/per_axis_error.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace arucoslam {

PerAxisError ComputePerAxisError(const Trajectory& gt, const Trajectory& est,
                                 const PerAxisErrorOptions& options) {
  if (gt.size() != est.size()) throw std::invalid_argument("ComputePerAxisError: sizes differ");
  if (!options.Check()) throw std::invalid_argument("PerAxisErrorOptions: invalid");
  PerAxisError result;
  result.count = gt.size();
  std::vector<Eigen::Vector3d> errors(gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) {
    errors[i] = (est.poses[i].translation - gt.poses[i].translation).cwiseAbs();
    result.mean_abs += errors[i];
    result.max_abs = result.max_abs.cwiseMax(errors[i]);
  }
  if (!errors.empty()) {
    result.mean_abs /= static_cast<double>(errors.size());
    for (const Eigen::Vector3d& e : errors) {
      result.std_abs += (e - result.mean_abs).cwiseAbs2();
    }
    result.std_abs = (result.std_abs / static_cast<double>(errors.size())).cwiseSqrt();
  }
  for (double requested : options.timestamps) {
    PerAxisSample sample;
    sample.requested_time = requested;
    double best = options.max_time_difference;
    for (std::size_t i = 0; i < gt.size(); ++i) {
      const double difference = std::abs(gt.timestamps[i] - requested);
      if (difference <= best && (!sample.found || difference < best)) {
        sample.found = true;
        best = difference;
        sample.time = gt.timestamps[i];
        sample.gt_position = gt.poses[i].translation;
        sample.est_position = est.poses[i].translation;
        sample.abs_error = errors[i];
      }
    }
    result.samples.push_back(sample);
  }
  return result;
}

}  // namespace arucoslam
