#include "arucoslam/eval/completeness.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "arucoslam/eval/statistics.h"

namespace arucoslam {

Completeness ComputeCompleteness(const Trajectory& gt, const Trajectory& est,
                                 const CompletenessOptions& options) {
  if (!options.Check()) throw std::invalid_argument("CompletenessOptions: invalid");
  Completeness result;
  if (gt.empty()) return result;
  const double start = gt.timestamps.front();
  const double end = gt.timestamps.back();
  result.gt_duration = end - start;
  double max_gap = options.max_gap;
  if (max_gap == 0.0 && est.size() >= 2) {
    std::vector<double> intervals;
    for (std::size_t i = 1; i < est.size(); ++i) {
      intervals.push_back(est.timestamps[i] - est.timestamps[i - 1]);
    }
    max_gap = 3.0 * Percentile(intervals, 50.0);
  }
  result.max_gap_used = max_gap;
  const auto note_gap = [&](double from, double to) {
    const double length = to - from;
    if (length > max_gap) ++result.num_gaps;
    if (length > result.longest_gap) {
      result.longest_gap = length;
      result.longest_gap_start = from;
    }
  };
  if (est.empty()) {
    note_gap(start, end);
    return result;
  }
  // Estimated stamps clipped to the ground-truth span.
  const double first = std::clamp(est.timestamps.front(), start, end);
  const double last = std::clamp(est.timestamps.back(), start, end);
  note_gap(start, first);
  for (std::size_t i = 1; i < est.size(); ++i) {
    const double a = std::clamp(est.timestamps[i - 1], start, end);
    const double b = std::clamp(est.timestamps[i], start, end);
    if (b - a <= max_gap) {
      result.covered_duration += b - a;
    } else {
      note_gap(a, b);
    }
  }
  note_gap(last, end);
  result.covered_fraction =
      result.gt_duration > 0.0 ? result.covered_duration / result.gt_duration : 1.0;
  return result;
}

}  // namespace arucoslam
