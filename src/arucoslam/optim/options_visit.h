// VisitOptions for the optim layer's options structs: each field once, with its comment
// (the protocol: util/options_visit.h). Config files are read and written from these.
#pragma once

#include "arucoslam/optim/bundle_adjustment.h"
#include "arucoslam/optim/essential_graph.h"
#include "arucoslam/optim/global_bundle_adjustment.h"
#include "arucoslam/optim/ground_plane_error.h"
#include "arucoslam/optim/local_bundle_adjustment.h"
#include "arucoslam/optim/marker_bundle_adjustment.h"
#include "arucoslam/optim/marker_factors.h"
#include "arucoslam/optim/marker_pose_optimizer.h"
#include "arucoslam/optim/pose_graph.h"
#include "arucoslam/optim/pose_optimizer.h"
#include "arucoslam/util/options_visit.h"

namespace arucoslam {

template <class Visitor>
void VisitOptions(BundleAdjustmentOptions& o, Visitor& visit) {
  // Not here: `stop_requested`, a callback the local mapper sets.
  visit("max_iterations", o.max_iterations, "Levenberg-Marquardt steps at most");
  visit("huber_delta_px", o.huber_delta_px,
        "Huber threshold on the reprojection residual, pixels at sigma 1");
  visit("chi_square_threshold", o.chi_square_threshold,
        "|r|^2 / sigma^2 above this after the solve: an outlier (2 dof, 95%)");
  visit("num_threads", o.num_threads, "solver threads");
  visit("function_tolerance", o.function_tolerance, "relative cost decrease that stops the solver");
  visit("min_iterations_before_stop", o.min_iterations_before_stop,
        "a solve asked to yield still takes this many iterations");
}

template <class Visitor>
void VisitOptions(MarkerFactorOptions& o, Visitor& visit) {
  visit("corner_sigma_px", o.corner_sigma_px, "marker corner noise, pixels");
  visit("marker_huber_delta", o.marker_huber_delta,
        "Huber threshold on a marker's whitened 8-vector norm");
  visit("marker_chi_square_threshold", o.marker_chi_square_threshold,
        "a marker observation above this |r|^2 / sigma^2 is an outlier (8 dof, 95%)");
  visit("min_prior_markers", o.min_prior_markers,
        "pose priors: a keyframe needs this many fixed markers in view");
  visit("prior_position_sigma_m", o.prior_position_sigma_m,
        "pose prior position sigma per marker seen, metres");
  visit("prior_rotation_sigma_rad", o.prior_rotation_sigma_rad,
        "pose prior rotation sigma per marker seen, radians");
  visit("max_prior_distance_sides", o.max_prior_distance_sides,
        "> 0: priors farther than this many marker sides are left out");
  visit("prior_from_corners", o.prior_from_corners,
        "true: a prior's covariance is its marker corners' own plus the sigmas above");
}

template <class Visitor>
void VisitOptions(LocalBundleAdjustmentOptions& o, Visitor& visit) {
  visit("solver", o.solver, "the solve");
  visit("max_covisible_keyframes", o.max_covisible_keyframes,
        "window: the keyframe and up to this many best covisible keyframes");
  visit("min_fixed_keyframes", o.min_fixed_keyframes,
        "fewer fixed anchor keyframes: the window's lowest-id ones are fixed too");
  visit("min_anchor_points", o.min_anchor_points,
        "a fixed keyframe anchors the gauge when it sees at least this many window points");
  visit("erase_outliers", o.erase_outliers, "erase the observations the solve flags");
  visit("min_relative_depth", o.min_relative_depth,
        "points nearer than this fraction of the keyframe's median depth are left out");
  visit("markers", o.markers, "marker-corner residuals of the window's keyframes");
}

template <class Visitor>
void VisitOptions(GlobalBundleAdjustmentOptions& o, Visitor& visit) {
  visit("solver", o.solver, "the solve");
  visit("num_fixed_keyframes", o.num_fixed_keyframes,
        "lowest-id keyframes held fixed (2 also fixes a monocular scale)");
  visit("erase_outliers", o.erase_outliers, "erase the observations the solve flags");
  visit("markers", o.markers, "marker-corner residuals");
}

template <class Visitor>
void VisitOptions(MarkerBundleAdjustmentOptions& o, Visitor& visit) {
  visit("solver", o.solver, "the keypoint side of the solve");
  visit("marker_huber_delta", o.marker_huber_delta,
        "Huber threshold on a marker's whitened 8-vector norm");
  visit("marker_chi_square_threshold", o.marker_chi_square_threshold,
        "a marker observation above this |r|^2 / sigma^2 is an outlier (8 dof, 95%)");
}

template <class Visitor>
void VisitOptions(GroundPlanePriorOptions& o, Visitor& visit) {
  visit("height_sigma_m", o.height_sigma_m, "keyframe height off the plane, metres");
  visit("tilt_sigma_rad", o.tilt_sigma_rad, "keyframe tilt off the mounting tilt, radians");
}

template <class Visitor>
void VisitOptions(PoseGraphOptions& o, Visitor& visit) {
  visit("max_iterations", o.max_iterations, "Levenberg-Marquardt iterations at most");
  visit("function_tolerance", o.function_tolerance, "relative cost decrease that stops the solver");
  visit("fix_scale", o.fix_scale, "every node keeps its scale (SE(3) graph; set for a metric map)");
  visit("num_threads", o.num_threads, "solver threads");
}

template <class Visitor>
void VisitOptions(EssentialGraphOptions& o, Visitor& visit) {
  visit("solver", o.solver, "the pose-graph solve");
  visit("min_covisibility_weight", o.min_covisibility_weight,
        "covisibility edges between keyframes sharing at least this many points");
  visit("edge_translation_sigma", o.edge_translation_sigma,
        "relative-pose edge sigma, translation, map units");
  visit("edge_rotation_sigma", o.edge_rotation_sigma, "relative-pose edge sigma, radians");
  visit("edge_scale_sigma", o.edge_scale_sigma, "relative-pose edge sigma, log scale");
}

template <class Visitor>
void VisitOptions(PoseOptimizationOptions& o, Visitor& visit) {
  visit("num_rounds", o.num_rounds, "outlier-classification rounds");
  visit("iterations_per_round", o.iterations_per_round, "Levenberg-Marquardt iterations per round");
  visit("num_robust_rounds", o.num_robust_rounds, "first rounds with the Huber loss");
  visit("huber_delta", o.huber_delta, "Huber threshold on the whitened residual");
  visit("chi_square_threshold", o.chi_square_threshold,
        "|r|^2 / sigma^2 above this: an outlier (2 dof, 95%)");
  visit("min_inliers", o.min_inliers, "fewer inliers after a round: failed");
}

template <class Visitor>
void VisitOptions(MarkerPoseOptimizationOptions& o, Visitor& visit) {
  visit("keypoints", o.keypoints, "rounds, iterations and the keypoints' robust loss and test");
  visit("marker_huber_delta", o.marker_huber_delta,
        "Huber threshold on a marker's whitened 8-vector norm");
  visit("marker_chi_square_threshold", o.marker_chi_square_threshold,
        "a marker above this |r|^2 / sigma^2 is an outlier (8 dof, 95%)");
}

}  // namespace arucoslam
