// Bundle adjustment of poses and points together with one radial coefficient k that a camera's
// calibration lacks: undistorted observations x are modelled as x_true (1 + k |x_true|^2).
#pragma once

#include <optional>
#include <string>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/optim/bundle_adjustment.h"

namespace arucoslam {

struct RadialRefinementSummary {
  // The joint solve: Ceres costs with k = 0 before and with k after; its RMS figures are the
  // pinhole reprojection's, without the radial term.
  BundleAdjustmentSummary solve;
  double k = 0.0;                 // the radial coefficient found
};

// Solves `problem` in place (its poses and points, as SolveBundleAdjustment does) with k
// estimated from 0. Pixels are the calibration's undistorted pixels; k acts on normalised
// coordinates (x - c) / f.
RadialRefinementSummary SolveBundleAdjustmentWithRadialTerm(const BundleAdjustmentOptions& options,
                                                            BundleAdjustmentProblem* problem);

// `camera` with k folded into its first radial coefficient (a distortion-free camera becomes
// radial-tangential): to first order the same correction. nullopt for the equidistant model,
// whose first coefficient is not the |x|^2 term.
std::optional<CameraModel> WithRadialTerm(const CameraModel& camera, double k);

}  // namespace arucoslam
