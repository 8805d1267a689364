// Global bundle adjustment of every keyframe and point of a Map (and, once it is in the marker
// world, of every marker-corner view) in three steps that let it run in the background:
// snapshot (read lock), solve (no lock), apply with corrections (write lock).
#pragma once

#include <string>
#include <vector>

#include "arucoslam/map/map.h"
#include "arucoslam/map/marker_landmark.h"
#include "arucoslam/optim/bundle_adjustment.h"
#include "arucoslam/optim/marker_factors.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct GlobalBundleAdjustmentOptions {
  BundleAdjustmentOptions solver;
  // The lowest-id keyframes held fixed (gauge). 2 (default) also fixes the scale of a
  // monocular map (with 1 the scale direction is free and the Schur complement can be
  // singular); 1 suffices when marker observations fix the scale.
  int num_fixed_keyframes = 2;
  // Erase observations the solve flags as outliers; points left with none are erased.
  bool erase_outliers = true;
  // Marker-corner residuals (when marker landmarks are given). A known (fixed) marker in view
  // holds position, orientation and scale: no keyframe is fixed then.
  MarkerFactorOptions markers;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Nested("solver", solver);
    check.AtLeast("num_fixed_keyframes", num_fixed_keyframes, 1);
    check.Nested("markers", markers);
    return check.ok();
  }
};

// The whole map as a BundleAdjustmentProblem plus the ids behind its indices and the poses
// before the solve (to carry the correction over to what was added in the meantime).
struct GlobalBundleAdjustmentSnapshot {
  BundleAdjustmentProblem problem;
  std::vector<KeyframeId> keyframe_ids;  // per problem pose
  std::vector<Rigid3> poses_before;      // per problem pose
  std::vector<MapPointId> point_ids;     // per problem point
  std::vector<int> keypoint_indices;     // per observation
  MarkerFactors markers;                 // the keyframes' marker views (none without landmarks)
};

struct GlobalBundleAdjustmentResult {
  bool applied = false;
  int num_keyframes = 0;
  int num_points = 0;
  int num_erased_observations = 0;
  int num_corrected_keyframes = 0;  // added after the snapshot, moved with their tree ancestor
  int num_corrected_points = 0;     // idem, moved with their reference keyframe
  int num_marker_observations = 0;  // marker-corner residual blocks (8-vectors)
  BundleAdjustmentSummary summary;
};

// With `landmarks`, every keyframe's views of them join the problem (read the landmarks
// while nothing edits them); the centres of `priors` join it either way (PositionPriorsOf).
GlobalBundleAdjustmentSnapshot TakeGlobalSnapshot(
    const MapData& data, const GlobalBundleAdjustmentOptions& options,
    const MarkerLandmarks* landmarks = nullptr, const std::vector<KeyframePosePrior>& priors = {});

// Solves the snapshot in place (keypoints, and marker corners when it has marker factors).
BundleAdjustmentSummary SolveGlobalSnapshot(const GlobalBundleAdjustmentOptions& options,
                                            GlobalBundleAdjustmentSnapshot* snapshot);

// Writes a solved snapshot back: solved keyframes and points take their new values (even if
// the map moved them since; stop other optimisers meanwhile); keyframes that are not in the
// snapshot follow their nearest spanning-tree ancestor that is (world correction
// T_before^-1 * T_after), points that are not follow their reference keyframe. Entities erased
// since are skipped. Solved mapped markers are written to `landmarks` when given. Fills the
// counters of `result`.
void ApplyGlobalBundleAdjustment(MapData& data, const GlobalBundleAdjustmentSnapshot& snapshot,
                                 const GlobalBundleAdjustmentOptions& options,
                                 GlobalBundleAdjustmentResult* result,
                                 MarkerLandmarks* landmarks = nullptr);

// Snapshot, solve and apply in one call (blocking; run it on a worker thread to keep
// tracking going: the map's lock is held only for the snapshot and the write-back).
GlobalBundleAdjustmentResult RunGlobalBundleAdjustment(
    Map& map, const GlobalBundleAdjustmentOptions& options = {},
    MarkerLandmarks* landmarks = nullptr);

}  // namespace arucoslam
