// Scale drift of a trajectory: the Sim(3) scale that fits it to the ground truth over
// consecutive time windows, to show a monocular map growing or shrinking as it goes.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "arucoslam/eval/association.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct ScaleDriftOptions {
  double window_s = 8.0;  // length of each window, seconds of ground-truth time
  // A window whose true positions spread less than this (RMS distance to their centroid, m)
  // is skipped: a camera turning on the spot gives no scale.
  double min_extent_m = 0.3;
  int min_pairs = 4;  // pose pairs a window needs

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Above("window_s", window_s, 0.0);
    check.AtLeast("min_extent_m", min_extent_m, 0.0);
    check.AtLeast("min_pairs", min_pairs, 3);
    return check.ok();
  }
};

struct ScaleDriftWindow {
  double start_s = 0.0;  // seconds from the first pair's ground-truth time
  double end_s = 0.0;
  std::size_t num_pairs = 0;
  // Length in the estimate per metre of the truth (the inverse of the fitted Sim3 scale):
  // 1 for a metric trajectory, below 1 where the estimate is too small.
  double estimate_per_truth = 1.0;
};

struct ScaleDrift {
  std::vector<ScaleDriftWindow> windows;  // in time order, the usable ones only
  double min = 0.0;                       // smallest and largest estimate_per_truth
  double max = 0.0;
  // Last window over the first, minus 1: -0.2 is a map that ended 20% smaller than it began.
  double last_over_first = 0.0;
};

// nullopt when fewer than two windows are usable. Throws std::invalid_argument on bad options.
std::optional<ScaleDrift> ComputeScaleDrift(const AssociatedTrajectories& pairs,
                                            const ScaleDriftOptions& options = {});

}  // namespace arucoslam
