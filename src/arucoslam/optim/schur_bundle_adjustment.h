// SolveBundleAdjustmentSchur: Levenberg-Marquardt on a BundleAdjustmentProblem with the points
// eliminated through an explicit Schur complement, for the small windows local mapping solves.
#pragma once

#include "arucoslam/optim/bundle_adjustment.h"

namespace arucoslam {

// Same problem, options and summary as SolveBundleAdjustment, and the same optimum: Huber
// on the whitened residual (iteratively reweighted, as Ceres corrects a loss with no
// curvature), points behind a camera contributing nothing, a Marquardt damping of the
// Hessian's diagonal adapted from the gain ratio. The reduced system over the free poses is
// dense (6 x free poses square) and solved by Cholesky; points are recovered per point.
// `num_iterations` counts the steps tried, accepted or not, as Ceres does.
BundleAdjustmentSummary SolveBundleAdjustmentSchur(const BundleAdjustmentOptions& options,
                                                   BundleAdjustmentProblem* problem);

}  // namespace arucoslam
