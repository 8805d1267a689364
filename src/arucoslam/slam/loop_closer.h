// LoopCloser: closes one detected loop synchronously: matches the current keyframe with the
// candidate, solves Sim3, fuses the duplicated points and optimises the essential graph.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/geometry/sim3_solver.h"
#include "arucoslam/map/map.h"
#include "arucoslam/optim/essential_graph.h"

namespace arucoslam {

struct LoopCloserOptions {
  // Matching of the two keyframes' keypoints that both carry a map point.
  BruteForceMatchOptions matching{50, 0.75, true, true, {}};
  Sim3SolverOptions sim3;
  // Loop-side points: those of the candidate and of this many of its best covisible keyframes.
  int loop_neighbours = 10;
  // Search by projection of the loop-side points (radius x scale(level), pixels; bits).
  double search_radius_px = 7.5;
  int max_projection_distance = 50;
  // Reprojection test of a projected match: squared error below chi2 x sigma^2 (2 dof, 95%).
  double reprojection_chi2 = 5.991;
  // The loop is accepted with at least this many matches (Sim3 inliers plus projected).
  int min_total_matches = 40;
  // The loop may rotate the current keyframe by at most this much (degrees). Measured on a
  // rendered factory loop: true loops asked for 29-44 degrees (monocular drift), look-alike
  // racks seen from the other side of the aisle for 177-179 degrees.
  double max_correction_rotation_deg = 60.0;
  // The current keyframe and this many of its best covisible keyframes are corrected with it.
  int correction_neighbours = 10;
  EssentialGraphOptions essential_graph;
  // Metric map (markers): rigid loop transform and SE(3) graph (overrides the fix_scale of
  // `sim3` and `essential_graph.solver`).
  bool metric_map = false;

  bool Check(std::string* why = nullptr) const;
};

struct LoopClosureResult {
  bool closed = false;
  std::string reason;   // why the loop was rejected
  int num_matches = 0;  // keypoint matches between the two keyframes
  int num_sim3_inliers = 0;
  int num_projected_matches = 0;  // further matches found by projection into current
  double correction_rotation_deg = 0.0;  // rotation the loop applies to the current keyframe
  int num_fused_points = 0;       // duplicates merged or observations added
  int num_corrected_keyframes = 0;
  Sim3 candidate_from_current;  // the solved loop transform
  EssentialGraphResult essential_graph;
};

class LoopCloser {
 public:
  explicit LoopCloser(Map& map, const LoopCloserOptions& options = {});

  // Switches to (or from) a metric map, e.g. once markers aligned it to the world: loops are
  // then solved and corrected rigidly, keeping the scale.
  void SetMetricMap(bool metric);
  // World-anchored map (markers): each loop's essential graph also takes these absolute pose
  // priors (asked for at each loop) with `graph`'s edge weights, and holds no keyframe fixed
  // when there are any. An empty source: loops are corrected about the loop keyframe alone.
  using PosePriorSource = std::function<std::vector<KeyframePosePrior>()>;
  void SetPosePriors(PosePriorSource source, const EssentialGraphOptions& graph);

  // Verifies the loop current -> candidate geometrically and, when it holds, corrects the
  // map. `candidate` comes from place recognition or from a shared marker.
  LoopClosureResult CloseLoop(KeyframeId current, KeyframeId candidate);

  // Set by every closed loop: a global bundle adjustment should run (in the background,
  // optim/global_bundle_adjustment.h); the caller clears it once started.
  bool global_bundle_adjustment_requested() const { return global_bundle_adjustment_requested_; }
  void ClearGlobalBundleAdjustmentRequest() { global_bundle_adjustment_requested_ = false; }
  // Keyframe pairs of the loops closed so far (they stay edges of later essential graphs).
  const std::vector<std::pair<KeyframeId, KeyframeId>>& closed_loops() const {
    return closed_loops_;
  }

 private:
  Map& map_;
  LoopCloserOptions options_;
  PosePriorSource pose_priors_;
  EssentialGraphOptions prior_graph_;
  bool global_bundle_adjustment_requested_ = false;
  std::vector<std::pair<KeyframeId, KeyframeId>> closed_loops_;
};

}  // namespace arucoslam
