// VisitOptions for the geometry layer's options structs: each field once, with its comment
// (the protocol: util/options_visit.h). Config files are read and written from these.
#pragma once

#include "arucoslam/geometry/pose_consistency.h"
#include "arucoslam/geometry/sim3_solver.h"
#include "arucoslam/geometry/world_motion_prior.h"
#include "arucoslam/util/options_visit.h"

namespace arucoslam {

template <class Visitor>
void VisitOptions(Sim3SolverOptions& o, Visitor& visit) {
  visit("max_ransac_iterations", o.max_ransac_iterations,
        "RANSAC: at most this many 3-point samples");
  visit("confidence", o.confidence, "RANSAC stops once an all-inlier sample is this probable");
  visit("chi_square_threshold", o.chi_square_threshold,
        "inlier when |r|^2 / sigma^2 is below this in both images (2 dof, 99%)");
  visit("min_inliers", o.min_inliers, "fewer inliers after refinement: no loop");
  visit("fix_scale", o.fix_scale, "rigid transform, scale 1 (set for a metric map)");
  visit("refine_iterations", o.refine_iterations,
        "Levenberg-Marquardt iterations on the inliers (0: no refinement)");
  visit("huber_delta", o.huber_delta, "Huber threshold of the refinement, whitened residual");
  visit("min_scale_baseline_ratio", o.min_scale_baseline_ratio,
        "below this baseline / median depth the refinement keeps the 3D fit's scale");
  visit("min_scale", o.min_scale, "a smaller scale is no loop");
  visit("max_scale", o.max_scale, "a larger scale is no loop");
  visit("seed", o.seed, "random sampling seed (deterministic)");
}

template <class Visitor>
void VisitOptions(WorldMotionPriorOptions& o, Visitor& visit) {
  visit("max_age_s", o.max_age_s, "a prediction needs a fix at most this old, seconds");
  visit("min_span_s", o.min_span_s, "... and an earlier one at least this before it, seconds");
  visit("max_span_s", o.max_span_s, "... and at most this before it, seconds");
}

template <class Visitor>
void VisitOptions(PoseConsistencyOptions& o, Visitor& visit) {
  visit("max_offset_m", o.max_offset_m,
        "a frame farther than this from the path between its keyframes is dropped, metres");
  visit("max_keyframe_gap_s", o.max_keyframe_gap_s,
        "checked between keyframes at most this far apart in time, seconds");
}

}  // namespace arucoslam
