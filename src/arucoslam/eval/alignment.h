// Trajectory alignment before an absolute error: none, SE(3) or Sim(3) (Umeyama, as evo's
// `align`), fitted on all pairs, the first N pairs, or the pairs inside a time window.
#pragma once

#include <optional>
#include <string>

#include "arucoslam/eval/association.h"
#include "arucoslam/geometry/sim3.h"

namespace arucoslam {

enum class AlignmentMode { kNone, kSe3, kSim3 };

// "none", "se3", "sim3" (case-insensitive); nullopt for anything else.
std::optional<AlignmentMode> ParseAlignmentMode(const std::string& name);
std::string AlignmentModeName(AlignmentMode mode);  // "none", "SE3", "Sim3"

struct AlignmentOptions {
  AlignmentMode mode = AlignmentMode::kNone;
  // Fit on the first N associated pairs only; 0 = all pairs.
  int first_poses = 0;
  // Fit on the pairs whose (ground-truth) timestamp lies in [start, end] seconds only.
  std::optional<double> window_start;
  std::optional<double> window_end;

  bool Check(std::string* why = nullptr) const;
};

struct AlignmentResult {
  AlignmentMode mode = AlignmentMode::kNone;
  Sim3 gt_from_est;            // identity for kNone; scale exactly 1 for kSe3
  std::size_t num_fitted = 0;  // pairs the fit used
};

// Fits gt_from_est to the associated positions. Returns nullopt when the selection holds
// fewer than 3 pairs or its positions are degenerate (all coincident).
std::optional<AlignmentResult> ComputeAlignment(const AssociatedTrajectories& pairs,
                                                const AlignmentOptions& options);

// Applies `gt_from_est` to every pose: position scaled, rotated and moved, orientation
// rotated (evo's `scale` then `transform`).
Trajectory ApplyAlignment(const Sim3& gt_from_est, const Trajectory& est);

}  // namespace arucoslam
