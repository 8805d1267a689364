#include "arucoslam/eval/scale_drift.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "arucoslam/eval/alignment.h"

namespace arucoslam {
namespace {

// RMS distance of `positions` to their centroid; 0 for none.
double Extent(const std::vector<Eigen::Vector3d>& positions) {
  if (positions.empty()) return 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : positions) centroid += p;
  centroid /= static_cast<double>(positions.size());
  double squared = 0.0;
  for (const Eigen::Vector3d& p : positions) squared += (p - centroid).squaredNorm();
  return std::sqrt(squared / static_cast<double>(positions.size()));
}

}  // namespace

std::optional<ScaleDrift> ComputeScaleDrift(const AssociatedTrajectories& pairs,
                                            const ScaleDriftOptions& options) {
  if (!options.Check()) throw std::invalid_argument("ScaleDriftOptions: invalid");
  if (pairs.size() < 2) return std::nullopt;
  const double t0 = pairs.gt.timestamps.front();
  const double t_end = pairs.gt.timestamps.back();
  ScaleDrift drift;
  for (double start = t0; start <= t_end; start += options.window_s) {
    const double end = start + options.window_s;
    std::vector<Eigen::Vector3d> true_positions;  // of the pairs in [start, end)
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const double t = pairs.gt.timestamps[i];
      if (t >= start && t < end) true_positions.push_back(pairs.gt.poses[i].translation);
    }
    if (true_positions.size() < static_cast<std::size_t>(options.min_pairs)) continue;
    if (Extent(true_positions) < options.min_extent_m) continue;
    AlignmentOptions alignment;
    alignment.mode = AlignmentMode::kSim3;
    alignment.window_start = start;
    // ComputeAlignment's window is closed; stop just short of the next window's first stamp.
    alignment.window_end = std::nextafter(end, start);
    const std::optional<AlignmentResult> fit = ComputeAlignment(pairs, alignment);
    if (!fit || !(fit->gt_from_est.scale > 0.0)) continue;
    drift.windows.push_back({start - t0, end - t0, fit->num_fitted, 1.0 / fit->gt_from_est.scale});
  }
  if (drift.windows.size() < 2) return std::nullopt;
  const auto [lowest, highest] =
      std::minmax_element(drift.windows.begin(), drift.windows.end(),
                          [](const ScaleDriftWindow& a, const ScaleDriftWindow& b) {
                            return a.estimate_per_truth < b.estimate_per_truth;
                          });
  drift.min = lowest->estimate_per_truth;
  drift.max = highest->estimate_per_truth;
  drift.last_over_first =
      drift.windows.back().estimate_per_truth / drift.windows.front().estimate_per_truth - 1.0;
  return drift;
}

}  // namespace arucoslam
