// Essential-graph optimisation of a Map after a loop closure: a Sim3 pose graph over all
// keyframes (spanning tree, strong covisibility and loop edges), then map points corrected.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "arucoslam/map/map.h"
#include "arucoslam/optim/pose_graph.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

// A closed loop: the Sim3 between the two keyframes' camera frames as the solver measured it.
struct LoopConstraint {
  KeyframeId current;
  KeyframeId candidate;
  Sim3 candidate_from_current;
};

// An absolute pose measurement of a keyframe (markers of known pose).
struct KeyframePosePrior {
  KeyframeId keyframe;
  Rigid3 world_from_cam;
  Matrix6d information = Matrix6d::Identity();  // over [centre, metres; rotation, radians]
};

struct EssentialGraphOptions {
  PoseGraphOptions solver;
  // Covisibility edges between keyframes sharing at least this many points (besides the
  // spanning tree and loops).
  int min_covisibility_weight = 100;
  // Standard deviations of a relative-pose edge's tangent [upsilon; omega; sigma]: metres
  // (map units), radians, log scale. 1, 1, 1: unit information (weights only matter
  // relative to the priors' and the loop edges').
  double edge_translation_sigma = 1.0;
  double edge_rotation_sigma = 1.0;
  double edge_scale_sigma = 1.0;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Nested("solver", solver);
    check.Above("min_covisibility_weight", min_covisibility_weight, 0);
    check.Above("edge_translation_sigma", edge_translation_sigma, 0.0);
    check.Above("edge_rotation_sigma", edge_rotation_sigma, 0.0);
    check.Above("edge_scale_sigma", edge_scale_sigma, 0.0);
    return check.ok();
  }
};

struct EssentialGraphResult {
  bool applied = false;  // solved and written to the map
  int num_keyframes = 0;
  int num_tree_edges = 0;
  int num_covisibility_edges = 0;
  int num_loop_edges = 0;
  int num_priors = 0;
  int num_corrected_points = 0;
  // Per keyframe: scale of its world correction (new map units per old unit around it); a
  // pose kept relative to the keyframe has its offset multiplied by it.
  std::map<KeyframeId, double> scale_changes;
  PoseGraphSummary summary;
};

// Sim3 estimates of `current` and its `num_neighbours` best covisible keyframes after the
// loop: current's pose becomes `current_cam_from_world_corrected`, each neighbour keeps its
// pose relative to current. The map is not changed (read under its lock).
std::map<KeyframeId, Sim3> PropagateLoopCorrection(const Map& map, KeyframeId current,
                                                   const Sim3& current_cam_from_world_corrected,
                                                   int num_neighbours);

// Optimises the essential graph and writes back keyframe poses (rigid: rotation and
// translation / scale) and every map point moved by its reference keyframe's correction
// (S_new^-1 * S_old). Edges are measured from the map's current (uncorrected) poses; nodes
// start at `corrected_cam_from_world` where given. `fixed_keyframe` is held (the loop
// keyframe), and so is every keyframe of `held_keyframes`. Keyframes added while the solver
// runs follow their spanning-tree ancestor.
EssentialGraphResult OptimizeEssentialGraph(
    Map& map, KeyframeId fixed_keyframe, const std::vector<LoopConstraint>& loops,
    const std::map<KeyframeId, Sim3>& corrected_cam_from_world = {},
    const std::vector<KeyframePosePrior>& priors = {}, const EssentialGraphOptions& options = {},
    const std::set<KeyframeId>& held_keyframes = {});

}  // namespace arucoslam
