// Time association of an estimated trajectory with ground truth, as evo does it: each pose of
// the shorter trajectory is paired with the closest stamp of the longer one within max_diff.
#pragma once

#include <string>
#include <vector>

#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct AssociationOptions {
  double max_time_difference = 0.01;  // seconds; a pair is kept when |t_gt - t_est| <= this

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("max_time_difference", max_time_difference, 0.0);
    return check.ok();
  }
};

// Pose pairs in the order of the shorter trajectory: gt.poses[i] <-> est.poses[i].
struct AssociatedTrajectories {
  Trajectory gt;
  Trajectory est;
  std::vector<std::size_t> gt_indices;   // index of each pair in the input ground truth
  std::vector<std::size_t> est_indices;  // index of each pair in the input estimate

  std::size_t size() const { return gt.size(); }
};

// evo's `sync.associate_trajectories(gt, est, max_diff)`: the shorter trajectory (the
// estimate when both have the same length) is walked; for each of its stamps the closest
// stamp of the other one is taken (the first on a tie) and kept when within
// max_time_difference. A stamp of the longer trajectory may be used twice. Timestamps must
// not decrease (the readers guarantee it). No pair is an empty result, not an error.
AssociatedTrajectories AssociateByTime(const Trajectory& gt, const Trajectory& est,
                                       const AssociationOptions& options);

// Pairs pose i with pose i (KITTI files without time); sizes must match.
AssociatedTrajectories AssociateByIndex(const Trajectory& gt, const Trajectory& est);

}  // namespace arucoslam
