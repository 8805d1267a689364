// Tracking completeness: how much of the ground-truth time span an estimate covers with
// poses, and its longest gap (before the first pose, between poses, after the last).
#pragma once

#include <string>

#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct CompletenessOptions {
  // Two consecutive estimated poses further apart than this (s) leave a gap between them;
  // 0 = automatic: 3 times the estimate's median frame interval.
  double max_gap = 0.0;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("max_gap", max_gap, 0.0);
    return check.ok();
  }
};

struct Completeness {
  double gt_duration = 0.0;        // s, last minus first ground-truth stamp
  double covered_duration = 0.0;   // s, of the ground-truth span covered by the estimate
  double covered_fraction = 0.0;   // covered_duration / gt_duration (1 for a zero span)
  double longest_gap = 0.0;        // s
  double longest_gap_start = 0.0;  // s, stamp where the longest gap begins
  int num_gaps = 0;                // gaps longer than the threshold, ends included
  double max_gap_used = 0.0;       // s, the threshold applied
};

// Both trajectories with non-decreasing stamps; an empty estimate covers nothing.
Completeness ComputeCompleteness(const Trajectory& gt, const Trajectory& est,
                                 const CompletenessOptions& options);

}  // namespace arucoslam
