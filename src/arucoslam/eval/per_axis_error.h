// Per-axis absolute position error (|dx|, |dy|, |dz| in the ground-truth world frame) as the
// paper's Table 1 reports it: statistics over the run and values at chosen timestamps.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct PerAxisErrorOptions {
  // Timestamps (s) at which to report the error; each takes the associated pair closest in
  // time, if one lies within max_time_difference.
  std::vector<double> timestamps;
  double max_time_difference = 0.1;  // seconds

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("max_time_difference", max_time_difference, 0.0);
    return check.ok();
  }
};

struct PerAxisSample {
  double requested_time = 0.0;  // s, as asked
  bool found = false;           // false: no pair within max_time_difference
  double time = 0.0;            // s, of the pair used
  Eigen::Vector3d gt_position = Eigen::Vector3d::Zero();   // m
  Eigen::Vector3d est_position = Eigen::Vector3d::Zero();  // m (aligned)
  Eigen::Vector3d abs_error = Eigen::Vector3d::Zero();     // m, |est - gt| per axis
};

struct PerAxisError {
  std::size_t count = 0;
  Eigen::Vector3d mean_abs = Eigen::Vector3d::Zero();  // m
  Eigen::Vector3d std_abs = Eigen::Vector3d::Zero();   // m (population)
  Eigen::Vector3d max_abs = Eigen::Vector3d::Zero();   // m
  std::vector<PerAxisSample> samples;                  // one per requested timestamp
};

// `gt` and `est` are associated pose pairs (same size); `est` already aligned.
PerAxisError ComputePerAxisError(const Trajectory& gt, const Trajectory& est,
                                 const PerAxisErrorOptions& options);

}  // namespace arucoslam
