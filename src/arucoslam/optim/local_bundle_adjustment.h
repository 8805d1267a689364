// RunLocalBundleAdjustment: bundle adjustment of a keyframe's covisibility neighbourhood in
// a Map (snapshot under a read lock, Ceres without the lock, results written back in one go).
#pragma once

#include <string>

#include "arucoslam/map/map.h"
#include "arucoslam/map/marker_landmark.h"
#include "arucoslam/optim/bundle_adjustment.h"
#include "arucoslam/optim/marker_factors.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct LocalBundleAdjustmentOptions {
  BundleAdjustmentOptions solver;
  // Local window: the keyframe and up to this many of its best covisible keyframes.
  int max_covisible_keyframes = 20;
  // Keyframes outside the window that observe its points are held fixed. When fewer than
  // this many fixed keyframes are anchors, the lowest-id keyframes of the window are fixed
  // too (the current keyframe last). The map's first keyframe is always fixed.
  int min_fixed_keyframes = 1;
  // A fixed border keyframe is an anchor (holds the gauge: position, rotation, and scale
  // with two) only when it observes at least this many window points. Border keyframes
  // seeing two or three points left the gauge nearly free and Ceres' Cholesky failed.
  int min_anchor_points = 20;
  // Erase observations the solve flags as outliers (chi-square test); points left with no
  // observation are erased.
  bool erase_outliers = true;
  // An observation whose point lies closer to the keyframe than this fraction of the
  // keyframe's median point depth (or behind it) is left out of the solve and erased with
  // the outliers: such points (bad matches placed next to a camera centre) have Jacobians
  // 1e4 times the others' and made Ceres' dense Cholesky fail.
  double min_relative_depth = 0.1;
  // Marker-corner residuals of the window's keyframes (when markers are given).
  MarkerFactorOptions markers;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Nested("solver", solver);
    check.AtLeast("max_covisible_keyframes", max_covisible_keyframes, 0);
    check.AtLeast("min_fixed_keyframes", min_fixed_keyframes, 0);
    check.AtLeast("min_anchor_points", min_anchor_points, 0);
    check.AtLeast("min_relative_depth", min_relative_depth, 0.0);
    check.Nested("markers", markers);
    return check.ok();
  }
};

struct LocalBundleAdjustmentResult {
  bool applied = false;  // the solve succeeded and its results were written to the map
  int num_local_keyframes = 0;
  int num_fixed_keyframes = 0;
  int num_points = 0;
  int num_erased_observations = 0;
  int num_too_near_observations = 0;  // left out for min_relative_depth (erased with outliers)
  int num_marker_observations = 0;  // marker-corner residual blocks (8-vectors)
  int num_moved_markers = 0;        // non-fixed markers whose pose was updated
  BundleAdjustmentSummary summary;
};

// Keyframes and points erased by another thread during the solve are skipped on write-back.
// With `markers`, the window's keyframes' marker observations join the solve (fixed markers
// held, the others estimated and written back); the caller owns `markers` exclusively.
LocalBundleAdjustmentResult RunLocalBundleAdjustment(
    Map& map, KeyframeId keyframe, const LocalBundleAdjustmentOptions& options = {},
    MarkerLandmarks* markers = nullptr);

}  // namespace arucoslam
