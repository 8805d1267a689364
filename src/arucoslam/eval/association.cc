#include "arucoslam/eval/association.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace arucoslam {
namespace {

// Index of the first stamp of `stamps` (sorted, not decreasing) closest to `t`, as
// numpy's argmin(|stamps - t|) finds it.
std::size_t ClosestIndex(const std::vector<double>& stamps, double t) {
  const auto upper = std::lower_bound(stamps.begin(), stamps.end(), t);
  std::size_t best = static_cast<std::size_t>(upper - stamps.begin());
  if (best == stamps.size()) --best;  // all stamps before t
  if (upper != stamps.begin()) {
    // The run of equal stamps just below t: its first element wins a tie.
    const double below = *(upper - 1);
    const std::size_t first_below = static_cast<std::size_t>(
        std::lower_bound(stamps.begin(), stamps.end(), below) - stamps.begin());
    if (upper == stamps.end() || std::abs(below - t) <= std::abs(*upper - t)) {
      best = first_below;
    }
  }
  return best;
}

}  // namespace

AssociatedTrajectories AssociateByTime(const Trajectory& gt, const Trajectory& est,
                                       const AssociationOptions& options) {
  if (!options.Check()) throw std::invalid_argument("AssociationOptions: max_time_difference < 0");
  AssociatedTrajectories out;
  if (gt.empty() || est.empty()) return out;
  const bool est_longer = est.size() > gt.size();
  const Trajectory& shorter = est_longer ? gt : est;
  const Trajectory& longer = est_longer ? est : gt;
  for (std::size_t i = 0; i < shorter.size(); ++i) {
    const std::size_t j = ClosestIndex(longer.timestamps, shorter.timestamps[i]);
    if (!(std::abs(longer.timestamps[j] - shorter.timestamps[i]) <= options.max_time_difference)) {
      continue;
    }
    const std::size_t gt_index = est_longer ? i : j;
    const std::size_t est_index = est_longer ? j : i;
    out.gt.AddFrom(gt, gt_index);
    out.est.AddFrom(est, est_index);
    out.gt_indices.push_back(gt_index);
    out.est_indices.push_back(est_index);
  }
  return out;
}

AssociatedTrajectories AssociateByIndex(const Trajectory& gt, const Trajectory& est) {
  if (gt.size() != est.size()) {
    throw std::invalid_argument("AssociateByIndex: trajectories differ in length");
  }
  AssociatedTrajectories out;
  out.gt = gt;
  out.est = est;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    out.gt_indices.push_back(i);
    out.est_indices.push_back(i);
  }
  return out;
}

}  // namespace arucoslam
