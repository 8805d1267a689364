// VisitOptions for the slam layer's options structs: each field once, with its comment
// (the protocol: util/options_visit.h). Config files are read and written from these.
#pragma once

#include "arucoslam/feature/options_visit.h"
#include "arucoslam/geometry/options_visit.h"
#include "arucoslam/markers/options_visit.h"
#include "arucoslam/optim/options_visit.h"
#include "arucoslam/slam/initializer.h"
#include "arucoslam/slam/keyframe_database.h"
#include "arucoslam/slam/keyframe_policy.h"
#include "arucoslam/slam/local_mapper.h"
#include "arucoslam/slam/loop_closer.h"
#include "arucoslam/slam/loop_detector.h"
#include "arucoslam/slam/map_initialization.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/marker_mapper.h"
#include "arucoslam/slam/radial_calibration.h"
#include "arucoslam/slam/relocalizer.h"
#include "arucoslam/slam/tracker.h"
#include "arucoslam/slam/world_alignment.h"
#include "arucoslam/slam/world_anchoring.h"
#include "arucoslam/slam/covisible_marker_vote.h"
#include "arucoslam/slam/world_rotation_vote.h"

namespace arucoslam {

template <class Visitor>
void VisitOptions(InitializerOptions& o, Visitor& visit) {
  visit("min_matches", o.min_matches, "fewer window matches: too few to initialise");
  visit("matching", o.matching, "window search from the reference frame into the current one");
  visit("ransac_iterations", o.ransac_iterations, "RANSAC iterations per model (H and F)");
  visit("sigma_px", o.sigma_px, "transfer residual noise, pixels");
  visit("seed", o.seed, "RANSAC seed (deterministic)");
  visit("homography_share", o.homography_share, "choose H when S_H / (S_H + S_F) exceeds this");
  visit("min_median_flow_px", o.min_median_flow_px,
        "median keypoint motion below this: a static camera, pixels");
  visit("min_translation_flow_px", o.min_translation_flow_px,
        "median motion left after the best rotation below this: a pure rotation, pixels");
  visit("min_parallax_deg", o.min_parallax_deg,
        "parallax the min_triangulated-th widest point must reach, degrees");
  visit("max_reprojection_px", o.max_reprojection_px,
        "per view, for a triangulated point to count, pixels");
  visit("min_triangulated", o.min_triangulated, "good triangulated points at least");
  visit("min_triangulated_fraction", o.min_triangulated_fraction,
        "good points at least this fraction of the chosen model's inliers");
  visit("relax_after_s", o.relax_after_s,
        "after this long on one reference, seconds, an unambiguous motion needs only ...");
  visit("relaxed_triangulated_fraction", o.relaxed_triangulated_fraction,
        "... this fraction of good points");
  visit("ambiguity_ratio", o.ambiguity_ratio,
        "ambiguous when the second-best motion explains more than this fraction of the points");
  visit("min_epipolar_support_ratio", o.min_epipolar_support_ratio,
        "candidate motions below this fraction of the best's epipolar support are ignored");
  visit("min_axis_agreement_cos", o.min_axis_agreement_cos,
        "the others must share the best's translation axis: |cos| at least this");
}

template <class Visitor>
void VisitOptions(InitialMapOptions& o, Visitor& visit) {
  visit("bundle_adjustment", o.bundle_adjustment, "refinement of both keyframes and the points");
  visit("min_points", o.min_points, "fewer points passing the test after refinement: rejected");
  visit("hold_motion", o.hold_motion, "refine the points only (motion known, e.g. from markers)");
}

template <class Visitor>
void VisitOptions(TrackerOptions& o, Visitor& visit) {
  visit("motion_search", o.motion_search,
        "motion model: the last frame's points projected with the predicted pose");
  visit("min_motion_matches", o.min_motion_matches,
        "fewer matches: search again with twice the radius, then fall back");
  visit("recovery_frames", o.recovery_frames,
        "after a loss the motion model keeps predicting for this many frames (0: no retry)");
  visit("max_prediction_gap_s", o.max_prediction_gap_s,
        "frames missing for up to this long count as motion-model steps, seconds");
  visit("reference_search", o.reference_search,
        "fallback: brute-force matching against the reference keyframe");
  visit("min_reference_matches", o.min_reference_matches, "matches needed by that fallback");
  visit("covisible_per_keyframe", o.covisible_per_keyframe,
        "local map: best covisible neighbours added per observing keyframe");
  visit("max_local_keyframes", o.max_local_keyframes, "local map: keyframes at most");
  visit("local_map_search", o.local_map_search,
        "projection search of local points (radius x 2.5 head-on, else x 4)");
  visit("min_view_cos", o.min_view_cos,
        "a point is searched when its mean view and the ray agree to this cosine");
  visit("min_pose_inliers", o.min_pose_inliers, "inliers needed after the first pose optimisation");
  visit("min_local_map_inliers", o.min_local_map_inliers, "inliers needed after the local map");
  visit("min_weak_inliers", o.min_weak_inliers,
        "fewer than min_local_map_inliers but this many: tracked if it agrees with the motion");
  visit("weak_max_rotation_deg", o.weak_max_rotation_deg,
        "weak view: rotation within this of the prediction, degrees");
  visit("weak_max_center_steps", o.weak_max_center_steps,
        "weak view: camera centre within this many frame motions of the prediction");
  visit("weak_radius_factor", o.weak_radius_factor,
        "motion model alone: local map searched with a window this many times wider");
  visit("pose", o.pose, "pose optimisation (its min_inliers is replaced by min_pose_inliers)");
  visit("marker_pose", o.marker_pose,
        "with known markers: marker-corner residuals (its keypoints part is replaced by pose)");
  visit("relocalization_min_axis_cos", o.relocalization_min_axis_cos,
        "tracking from a given pose: nearest keyframe with its optical axis within this cosine");
  visit("update_point_statistics", o.update_point_statistics,
        "count local-map searches in the points' visible/found statistics");
}

template <class Visitor>
void VisitOptions(KeyframePolicyOptions& o, Visitor& visit) {
  visit("min_frames_between", o.min_frames_between,
        "frames after a keyframe before the next while the mapper is idle");
  visit("max_frames_between", o.max_frames_between,
        "after this many frames a keyframe even with a busy mapper (queue room permitting)");
  visit("tracked_ratio", o.tracked_ratio,
        "insert when tracking fewer than this fraction of the reference keyframe's points");
  visit("min_observations", o.min_observations,
        "reference points count with at least this many observing keyframes");
  visit("min_tracked_points", o.min_tracked_points,
        "a frame with this many inliers or fewer never becomes a keyframe");
  visit("weak_ratio", o.weak_ratio, "weak tracking: fewer than this x the reference's points");
  visit("weak_tracked_points", o.weak_tracked_points, "... or fewer inliers than this");
  visit("weak_min_frames_between", o.weak_min_frames_between, "frames between two weak keyframes");
}

template <class Visitor>
void VisitOptions(LocalMapperOptions& o, Visitor& visit) {
  visit("triangulation_neighbours", o.triangulation_neighbours,
        "triangulation pairs the new keyframe with up to this many best covisible ones");
  visit("min_baseline_depth_ratio", o.min_baseline_depth_ratio,
        "a pair with baseline / median depth below this is skipped");
  visit("max_match_distance", o.max_match_distance, "triangulation match distance, bits");
  visit("match_ratio", o.match_ratio, "best < ratio x second best among epipolar candidates");
  visit("epipolar_chi2", o.epipolar_chi2,
        "squared epipolar distance below this x sigma^2 (1 dof, 95%)");
  visit("min_epipole_distance_px", o.min_epipole_distance_px,
        "candidates nearer the epipole than this x scale(level) are skipped, pixels");
  visit("max_parallax_cos", o.max_parallax_cos, "rays must make an angle with cosine below this");
  visit("reprojection_chi2", o.reprojection_chi2,
        "per-view squared reprojection error below this x sigma^2 (2 dof, 95%)");
  visit("scale_consistency_factor", o.scale_consistency_factor,
        "distance and pyramid scale ratios may differ by this x the scale factor");
  visit("multi_view_check", o.multi_view_check,
        "a point matched in several neighbours must reproject into each of them");
  visit("fusion_neighbours", o.fusion_neighbours,
        "fusion: neighbours the points are projected into");
  visit("fusion_radius_px", o.fusion_radius_px, "fusion search radius x scale(level), pixels");
  visit("fusion_max_distance", o.fusion_max_distance, "fusion match distance, bits");
  visit("min_found_ratio", o.min_found_ratio, "recent point culling: found / visible below this");
  visit("min_point_observations", o.min_point_observations,
        "... or fewer observations two keyframes after creation");
  visit("run_bundle_adjustment", o.run_bundle_adjustment, "local bundle adjustment per keyframe");
  visit("bundle_adjustment", o.bundle_adjustment, "the local bundle adjustment");
  visit("redundant_fraction", o.redundant_fraction,
        "keyframe culling: this fraction of its points seen by redundant_observers others");
  visit("redundant_observers", o.redundant_observers, "... at the same or a finer scale");
  visit("min_keyframe_points", o.min_keyframe_points,
        "an older keyframe with fewer map points than this is erased too");
  visit("cull_keyframes", o.cull_keyframes, "erase redundant keyframes");
  visit("min_marker_keyframes", o.min_marker_keyframes,
        "a keyframe stays while one of its markers is seen by fewer other keyframes");
}

template <class Visitor>
void VisitOptions(WorldAlignmentOptions& o, Visitor& visit) {
  visit("ambiguous_weight", o.ambiguous_weight,
        "weight of an ambiguous anchor, in [0, 1] (0: left out)");
  visit("outlier_threshold_m", o.outlier_threshold_m,
        "an anchor farther than this from its marker position after alignment is an outlier, m");
  visit("collinear_ratio", o.collinear_ratio,
        "centres collinear when the 2nd scatter eigenvalue is below this fraction of the 1st");
}

template <class Visitor>
void VisitOptions(MarkerMapperOptions& o, Visitor& visit) {
  visit("unknown_marker_size_m", o.unknown_marker_size_m,
        "side of markers absent from the known map, metres (0: the first known marker's)");
  visit("map_unknown", o.map_unknown, "map markers absent from the known map");
  visit("marker_pose", o.marker_pose, "IPPE ambiguity test of a single view");
  visit("max_view_angle_deg", o.max_view_angle_deg,
        "a keyframe's detection of a mapped marker seen beyond this angle is a misread, degrees");
  visit("max_detection_offset_ratio", o.max_detection_offset_ratio,
        "... or one whose own pose puts the camera farther from the keyframe than this times "
        "the marker's distance");
  visit("max_initial_rms_px", o.max_initial_rms_px,
        "a first view reprojecting worse than this does not initialise, RMS pixels");
  visit("min_consistent_views", o.min_consistent_views,
        "a marker is mapped once this many keyframes saw it at agreeing poses (>= 2)");
  visit("max_view_disagreement_m", o.max_view_disagreement_m,
        "views agree within this marker-centre distance, metres ...");
  visit("max_view_disagreement_fraction", o.max_view_disagreement_fraction,
        "... plus this fraction of the view's distance");
  visit("max_pending_views", o.max_pending_views,
        "views an unmapped marker keeps (oldest dropped)");
  visit("marker_views", o.marker_views,
        "frames posed by markers alone map unknown markers too (no keypoint map needed)");
  visit("marker_view_min_translation_fraction", o.marker_view_min_translation_fraction,
        "a marker view is taken this fraction of its nearest marker's distance from the others");
  visit("marker_view_min_rotation_deg", o.marker_view_min_rotation_deg,
        "... or turned this many degrees from them");
  visit("corner_sigma_px", o.corner_sigma_px, "corner noise of the adjustment, pixels");
  visit("balance_corner_sigma", o.balance_corner_sigma,
        "re-estimate the corner sigma from the residuals and solve again");
  visit("min_corner_sigma_px", o.min_corner_sigma_px, "that sigma at least, pixels");
  visit("max_corner_sigma_px", o.max_corner_sigma_px, "that sigma at most, pixels");
  visit("bundle_adjustment", o.bundle_adjustment, "the adjustment with the map (Refine)");
  visit("ground_plane_prior", o.ground_plane_prior,
        "ground vehicle on a level floor (run --ground-vehicle): keyframes held near one plane");
}

template <class Visitor>
void VisitOptions(KeyframeDatabaseOptions& o, Visitor& visit) {
  visit("direct_index_depth", o.direct_index_depth,
        "depth of the direct index's vocabulary nodes (>= 1)");
}

template <class Visitor>
void VisitOptions(CandidateGroupingOptions& o, Visitor& visit) {
  visit("min_shared_words_ratio", o.min_shared_words_ratio,
        "matches sharing fewer words than this fraction of the best's are dropped, (0, 1]");
  visit("group_size", o.group_size, "a match's group: it and its best covisible matches");
  visit("min_group_score_ratio", o.min_group_score_ratio,
        "groups scoring below this fraction of the best are dropped, (0, 1]");
  visit("max_candidates", o.max_candidates, "candidates returned at most");
}

template <class Visitor>
void VisitOptions(RelocalizerOptions& o, Visitor& visit) {
  visit("max_query_results", o.max_query_results, "database matches considered, best first");
  visit("grouping", o.grouping, "grouping of the matches into candidate keyframes");
  visit("max_bow_distance", o.max_bow_distance, "BoW-guided matching distance, bits");
  visit("bow_ratio", o.bow_ratio, "best < ratio x second best");
  visit("check_rotation", o.check_rotation, "drop matches off the dominant rotation");
  visit("min_bow_matches", o.min_bow_matches, "BoW matches needed");
  visit("pnp_threshold_px", o.pnp_threshold_px, "PnP RANSAC reprojection threshold, pixels");
  visit("pnp_iterations", o.pnp_iterations, "PnP RANSAC iterations");
  visit("pnp_confidence", o.pnp_confidence, "PnP RANSAC confidence");
  visit("min_pnp_inliers", o.min_pnp_inliers, "PnP inliers needed to go on");
  visit("pose", o.pose, "pose optimisation");
  visit("projection_neighbours", o.projection_neighbours,
        "guided search: the candidate's points and its best covisible keyframes'");
  visit("wide_search", o.wide_search, "the first projection pass");
  visit("narrow_search", o.narrow_search, "the second pass when inliers fall short");
  visit("min_inliers", o.min_inliers, "inliers after the last optimisation to relocalise");
}

template <class Visitor>
void VisitOptions(LoopDetectorOptions& o, Visitor& visit) {
  visit("min_keyframes_in_map", o.min_keyframes_in_map, "no detection in a smaller map");
  visit("exclude_min_weight", o.exclude_min_weight,
        "keyframes sharing this many points with the current one are never candidates");
  visit("reference_min_weight", o.reference_min_weight,
        "reference score from neighbours sharing at least this many points");
  visit("min_score_ratio", o.min_score_ratio, "matches score at least this x the reference");
  visit("max_query_results", o.max_query_results, "database matches considered, best first");
  visit("grouping", o.grouping, "grouping of the matches into candidates");
  visit("min_consistent_keyframes", o.min_consistent_keyframes,
        "a candidate group must persist over this many keyframes");
  visit("max_marker_candidates", o.max_marker_candidates,
        "marker candidates at most, most shared markers first");
}

template <class Visitor>
void VisitOptions(LoopCloserOptions& o, Visitor& visit) {
  visit("matching", o.matching, "matching of the two keyframes' keypoints with map points");
  visit("sim3", o.sim3, "the Sim3 RANSAC and refinement");
  visit("loop_neighbours", o.loop_neighbours,
        "loop-side points: the candidate's and its best covisible keyframes'");
  visit("search_radius_px", o.search_radius_px, "projection search radius x scale(level), pixels");
  visit("max_projection_distance", o.max_projection_distance, "projection match distance, bits");
  visit("reprojection_chi2", o.reprojection_chi2,
        "projected match: squared error below this x sigma^2 (2 dof, 95%)");
  visit("min_total_matches", o.min_total_matches, "Sim3 inliers plus projected matches needed");
  visit("max_correction_rotation_deg", o.max_correction_rotation_deg,
        "the loop may rotate the current keyframe by at most this, degrees");
  visit("correction_neighbours", o.correction_neighbours,
        "best covisible keyframes corrected with the current one");
  visit("essential_graph", o.essential_graph, "the pose-graph correction");
  visit("metric_map", o.metric_map, "rigid loops, SE(3) graph (set for a marker map)");
}

template <class Visitor>
void VisitOptions(WorldRotationVoteOptions& o, Visitor& visit) {
  visit("agreement_deg", o.agreement_deg, "two views' hypotheses agree within this, degrees");
  visit("min_support", o.min_support, "views agreeing with the winner, itself included");
  visit("min_margin", o.min_margin, "the winner's support over the best rival's (> 1)");
  visit("max_views", o.max_views, "views kept, the newest");
}

template <class Visitor>
void VisitOptions(CovisibleMarkerVoteOptions& o, Visitor& visit) {
  visit("max_frames", o.max_frames, "ambiguous frames kept to vote with, the newest");
  visit("max_disagreement_m", o.max_disagreement_m,
        "a marker centre agrees between two frames within this, metres ...");
  visit("max_disagreement_fraction", o.max_disagreement_fraction,
        "... plus this fraction of its distance");
  visit("min_agreement_margin", o.min_agreement_margin,
        "a frame pair votes when one solution puts this many more markers in agreement");
  visit("min_votes", o.min_votes, "votes for one solution (none for the other) that settle it");
}

template <class Visitor>
void VisitOptions(MarkerFusionOptions& o, Visitor& visit) {
  visit("locator", o.locator, "camera pose from the markers (LocateCamera)");
  visit("max_marker_rms_px", o.max_marker_rms_px,
        "a marker location is used with a corner RMS at most this, pixels");
  visit("max_marker_distance_sides", o.max_marker_distance_sides,
        "... and its nearest marker at most this many marker sides away");
  visit("resolve_ambiguity_by_motion", o.resolve_ambiguity_by_motion,
        "an ambiguous one-marker location settled by a motion prediction");
  visit("ambiguity_gates", o.ambiguity_gates, "gates of that prediction");
  visit("fix_motion", o.fix_motion, "constant-velocity prediction from recent marker fixes");
  visit("resolve_ambiguity_by_map_rotation", o.resolve_ambiguity_by_map_rotation,
        "unaligned map: ambiguous markers settled by the map's voted world orientation");
  visit("rotation_vote", o.rotation_vote, "that vote");
  visit("map_rotation_gates", o.map_rotation_gates, "gates of the voted orientation");
  visit("resolve_ambiguity_by_covisible_markers", o.resolve_ambiguity_by_covisible_markers,
        "else: ambiguous markers settled by the unknown markers seen with them");
  visit("covisible_vote", o.covisible_vote, "that vote");
  visit("max_marker_disagreement_m", o.max_marker_disagreement_m,
        "a keypoint pose farther than this from the frame's marker location is wrong, metres");
}

template <class Visitor>
void VisitOptions(WorldAnchoringOptions& o, Visitor& visit) {
  visit("alignment", o.alignment, "keypoint map to marker world alignment (Sim3)");
  visit("min_alignment_anchors", o.min_alignment_anchors,
        "world alignment waits for this many keyframes with a marker location");
  visit("min_alignment_baseline_m", o.min_alignment_baseline_m,
        "... whose camera centres span at least this, metres");
  visit("max_alignment_rms_m", o.max_alignment_rms_m,
        "alignment refused above this anchor residual, metres");
  visit("max_alignment_scale", o.max_alignment_scale,
        "a first alignment with a larger scale is refused (collapsed map)");
  visit("max_realignment_anchors", o.max_realignment_anchors,
        "realigned each time the anchors double, up to this many");
  visit("drift_correction", o.drift_correction,
        "pose-graph correction of the aligned map when a keyframe's markers disagree");
  visit("min_marker_correction_m", o.min_marker_correction_m,
        "a drift correction needs a disagreement beyond this, metres ...");
  visit("marker_correction_sigmas", o.marker_correction_sigmas,
        "... and beyond this many standard deviations of the marker pose");
  visit("marker_priors", o.marker_priors, "keyframe marker locations as priors");
  visit("marker_correction_graph", o.marker_correction_graph,
        "the pose graph of marker corrections");
  visit("priors_in_loops", o.priors_in_loops,
        "loops in the aligned map corrected with the marker priors");
}

template <class Visitor>
void VisitOptions(RadialCalibrationOptions& o, Visitor& visit) {
  visit("enabled", o.enabled,
        "refine the camera's radial distortion from the map (keypoint-only runs)");
  visit("first_keyframes", o.first_keyframes,
        "first attempt at this many keyframes, each later one at twice the count before");
  visit("max_attempts", o.max_attempts, "attempts at most");
  visit("min_cost_decrease", o.min_cost_decrease,
        "kept when the whole-map cost falls by at least this fraction with the correction");
  visit("max_abs_k", o.max_abs_k,
        "... and the correction stays within this, normalised coordinates");
  visit("solver", o.solver, "the whole-map solves");
}

template <class Visitor>
void VisitOptions(MapSessionOptions& o, Visitor& visit) {
  visit("reset_max_keyframes", o.reset_max_keyframes,
        "lost with at most this many keyframes, not in the world: discarded, initialised again");
  visit("marker_reset_lost_frames", o.marker_reset_lost_frames,
        "aligned map lost this many frames while markers give poses: a new map");
  visit("new_map_after_lost_s", o.new_map_after_lost_s,
        "lost this long and not relocalised: a new map, seconds");
  visit("merge_closed_maps", o.merge_closed_maps,
        "a closed aligned map is merged into the next map once that one is aligned");
  visit("bridge_tracking_gaps", o.bridge_tracking_gaps,
        "a gap between two aligned maps bridged by a constant-velocity prediction");
  visit("bridge_motion", o.bridge_motion, "that prediction");
  visit("bridge_position_sigma_m", o.bridge_position_sigma_m,
        "its position sigma, metres, plus ...");
  visit("bridge_position_sigma_per_s", o.bridge_position_sigma_per_s,
        "... this per second of gap, metres per second");
  visit("bridge_rotation_sigma_rad", o.bridge_rotation_sigma_rad,
        "its rotation sigma, radians, plus ...");
  visit("bridge_rotation_sigma_per_s", o.bridge_rotation_sigma_per_s,
        "... this per second of gap, radians per second");
  visit("bridge_in_bundle_adjustment", o.bridge_in_bundle_adjustment,
        "the bridge's camera centre stays a prior in whole-map bundle adjustments");
  visit("bridge_max_acceleration_m_s2", o.bridge_max_acceleration_m_s2,
        "its sigma there grows with this x gap^2 / 2, metres per second squared");
  visit("max_backfill_frames", o.max_backfill_frames,
        "frames before initialisation tracked backwards against the new map (0: none)");
}

}  // namespace arucoslam
