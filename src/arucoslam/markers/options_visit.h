// VisitOptions for the markers layer's options structs: each field once, with its comment
// (the protocol: util/options_visit.h). Config files are read and written from these.
#pragma once

#include <span>

#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/markers/candidate_decoder.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/detector_regions.h"
#include "arucoslam/markers/edge_refiner.h"
#include "arucoslam/markers/marker_pose.h"
#include "arucoslam/markers/threshold_line_fit.h"
#include "arucoslam/util/options_visit.h"

namespace arucoslam {

// CornerRefinement's names in config files and on the command line (`locate --refinement`).
inline constexpr EnumName<CornerRefinement> kCornerRefinementNames[] = {
    {CornerRefinement::kNone, "none"},
    {CornerRefinement::kSubpix, "subpix"},
    {CornerRefinement::kContour, "contour"},
    {CornerRefinement::kAprilTag, "apriltag"}};
inline std::span<const EnumName<CornerRefinement>> EnumNames(CornerRefinement) {
  return kCornerRefinementNames;
}

template <class Visitor>
void VisitOptions(EdgeRefineOptions& o, Visitor& visit) {
  visit("search_cells", o.search_cells,
        "edge points searched this far along the side's normal, marker cells (< 1)");
  visit("iterations", o.iterations, "refits of the four sides");
  visit("min_edge_fraction", o.min_edge_fraction,
        "a side keeps its refit with at least this fraction of its samples on an edge");
  visit("min_step", o.min_step, "dark-to-bright step of an edge point over 2 px, grey levels");
  visit("max_shift_cells", o.max_shift_cells, "a corner moving further fails, cells");
  visit("derivative_half_width_px", o.derivative_half_width_px,
        "half width of the grey profile's derivative, pixels");
}

template <class Visitor>
void VisitOptions(CandidateDecoderOptions& o, Visitor& visit) {
  visit("marker_border_bits", o.marker_border_bits,
        "black border width, cells (the detector's marker_border_bits is used)");
  visit("samples_per_cell", o.samples_per_cell, "a cell is the mean of n x n bilinear samples");
  visit("ignored_margin_per_cell", o.ignored_margin_per_cell,
        "cell margin left out of the samples, fraction of a cell in [0, 0.5)");
  visit("min_contrast", o.min_contrast, "between dark and bright cell means, grey levels");
  visit("max_erroneous_border_bits", o.max_erroneous_border_bits,
        "white cells tolerated in the black border");
  visit("error_correction_rate", o.error_correction_rate,
        "fraction of the dictionary's correction capacity, [0, 1]");
  visit("refine_window_cells", o.refine_window_cells,
        "cornerSubPix half window before reading, fraction of a cell (at least 2 px)");
  visit("max_refine_shift_cells", o.max_refine_shift_cells,
        "a corner moving further drops the candidate, cells");
  visit("edge_refinement", o.edge_refinement, "corners from the four sides' edges first");
  visit("edges", o.edges, "that edge refinement");
  visit("ring_threshold", o.ring_threshold,
        "cells thresholded between the border's black and the quiet zone's white (else Otsu)");
  visit("sharpening", o.sharpening, "cell += sharpening x its Laplacian before thresholding");
}

template <class Visitor>
void VisitOptions(ThresholdLineFitOptions& o, Visitor& visit) {
  visit("tile_px", o.tile_px, "tiles of the local min/max threshold, pixels");
  visit("min_contrast", o.min_contrast,
        "a pixel is neither dark nor bright below this local contrast, grey levels");
  visit("band_cells", o.band_cells, "a crossing belongs to a side within this, marker cells");
  visit("min_band_px", o.min_band_px, "that band at least, pixels");
  visit("max_band_px", o.max_band_px, "that band at most, pixels");
  visit("iterations", o.iterations, "crossings re-assigned to the refitted lines");
  visit("min_points_per_side", o.min_points_per_side, "crossings needed per side");
  visit("max_shift_cells", o.max_shift_cells, "a corner moving further fails the fit, cells");
}

template <class Visitor>
void VisitOptions(DetectorOptions& o, Visitor& visit) {
  // Not here: `dictionary`, which the marker map (markers.json) gives.
  visit("adaptive_thresh_win_size_min", o.adaptive_thresh_win_size_min,
        "smallest adaptive threshold window (odd side), pixels");
  visit("adaptive_thresh_win_size_max", o.adaptive_thresh_win_size_max,
        "largest adaptive threshold window, pixels");
  visit("adaptive_thresh_win_size_step", o.adaptive_thresh_win_size_step,
        "step between window sides, pixels");
  visit("adaptive_thresh_constant", o.adaptive_thresh_constant,
        "subtracted from the local mean, grey levels");
  visit("min_marker_perimeter_rate", o.min_marker_perimeter_rate,
        "smallest candidate perimeter, fraction of the larger image side");
  visit("max_marker_perimeter_rate", o.max_marker_perimeter_rate,
        "largest candidate perimeter, fraction of the larger image side");
  visit("polygonal_approx_accuracy_rate", o.polygonal_approx_accuracy_rate,
        "polygon fit accuracy, fraction of the candidate's perimeter");
  visit("min_corner_distance_rate", o.min_corner_distance_rate,
        "corners at least this far apart, fraction of the perimeter");
  visit("min_distance_to_border", o.min_distance_to_border,
        "corners at least this far from the image border, pixels");
  visit("min_marker_distance_rate", o.min_marker_distance_rate,
        "OpenCV's too-close-candidates filter (0: off, duplicates removed by dedup_distance_rate)");
  visit("corner_refinement", o.corner_refinement, "none, subpix, contour or apriltag");
  visit("corner_refinement_win_size", o.corner_refinement_win_size,
        "largest subpix half window, pixels");
  visit("corner_refinement_window_cells", o.corner_refinement_window_cells,
        "subpix half window, fraction of a marker cell (clamped to [2, win_size] px)");
  visit("corner_refinement_max_iterations", o.corner_refinement_max_iterations,
        "subpix iterations at most");
  visit("corner_refinement_min_accuracy", o.corner_refinement_min_accuracy,
        "subpix stops below this corner motion, pixels");
  visit("perspective_remove_pixel_per_cell", o.perspective_remove_pixel_per_cell,
        "pixels per cell when decoding");
  visit("perspective_remove_ignored_margin_per_cell", o.perspective_remove_ignored_margin_per_cell,
        "cell margin ignored, fraction of a cell");
  visit("max_erroneous_bits_in_border_rate", o.max_erroneous_bits_in_border_rate,
        "wrong border bits tolerated, fraction of the border");
  visit("min_otsu_std_dev", o.min_otsu_std_dev,
        "below this grey spread a candidate is one colour, grey levels");
  visit("error_correction_rate", o.error_correction_rate,
        "fraction of the dictionary's correction capacity");
  visit("detect_inverted_marker", o.detect_inverted_marker, "also white-on-black markers");
  visit("marker_border_bits", o.marker_border_bits,
        "black border width, cells (2 for Kalibr-style AprilGrids)");
  visit("april_tag_quad_decimate", o.april_tag_quad_decimate,
        "apriltag refinement: image decimation before quad detection (0 or 1: none)");
  visit("april_tag_quad_sigma", o.april_tag_quad_sigma,
        "apriltag refinement: Gaussian blur sigma, pixels");
  visit("dedup_distance_rate", o.dedup_distance_rate,
        "same-id detections closer than this fraction of a side are one marker");
  visit("upsample", o.upsample, "image scale before detection, in [1, 8] (1: none)");
  visit("rescue_rejected", o.rescue_rejected,
        "decode OpenCV's rejected candidates again with sub-pixel sampling (`rescue`)");
  visit("rescue", o.rescue, "the decoder of rejected candidates");
  visit("rescue_contour_candidates", o.rescue_contour_candidates,
        "apriltag refinement with rescue: also decode the contour search's candidates");
  visit("threshold_line_fit", o.threshold_line_fit,
        "refit every detection's corners to local-threshold crossings");
  visit("threshold_fit", o.threshold_fit, "that threshold line fit");
  visit("edge_refinement", o.edge_refinement,
        "subpix, 1-cell border: refit the corners of mid-sized markers from their edges");
  visit("edge_refinement_min_side_px", o.edge_refinement_min_side_px,
        "markers at least this side get the edge refit, pixels");
  visit("edge_refinement_max_side_px", o.edge_refinement_max_side_px,
        "markers at most this side get the edge refit, pixels");
  visit("edge_refinement_options", o.edge_refinement_options, "that edge refit");
  visit("april_tag_quad_corners", o.april_tag_quad_corners,
        "AprilTag dictionaries, 1-cell border: corners from a matching AprilTag quad fit");
  visit("april_tag_quad_match_cells", o.april_tag_quad_match_cells,
        "a quad matches with every corner within this many cells (> 0)");
}

template <class Visitor>
void VisitOptions(MarkerSearchOptions& o, Visitor& visit) {
  visit("full_scan_interval", o.full_scan_interval,
        "whole-image search every this many frames (1: always), else around known markers");
  visit("grow_rate", o.grow_rate, "search regions grow by this x their size");
  visit("pose_margin_px", o.pose_margin_px,
        "projected markers' regions grow by this more (the pose's error), pixels");
  visit("max_region_area", o.max_region_area,
        "regions over this fraction of the image: the whole image is searched");
}

template <class Visitor>
void VisitOptions(MarkerPoseOptions& o, Visitor& visit) {
  visit("ambiguity_ratio", o.ambiguity_ratio,
        "ambiguous when best / second IPPE error exceeds this, in (0, 1]");
  visit("min_distinct_error_px", o.min_distinct_error_px,
        "... or when the second error is below this, RMS pixels");
}

template <class Visitor>
void VisitOptions(CameraLocatorOptions& o, Visitor& visit) {
  visit("inlier_threshold_px", o.inlier_threshold_px, "corner inlier reprojection error, pixels");
  visit("ransac_iterations", o.ransac_iterations, "RANSAC PnP iterations with several markers");
  visit("ransac_confidence", o.ransac_confidence, "RANSAC confidence, in (0, 1)");
  visit("min_inlier_corners", o.min_inlier_corners, "fewer inlier corners: no pose");
  visit("refine_max_iterations", o.refine_max_iterations,
        "Levenberg-Marquardt iterations (0: no refinement)");
  visit("max_view_angle_deg", o.max_view_angle_deg,
        "a pose showing a marker from behind or more edge-on than this explains none of it, "
        "degrees");
  visit("marker_pose", o.marker_pose, "per-marker IPPE and its ambiguity test");
}

template <class Visitor>
void VisitOptions(AmbiguityPriorGates& o, Visitor& visit) {
  visit("max_rotation_deg", o.max_rotation_deg,
        "a predicted pose settles on a solution within this rotation of it, degrees");
  visit("max_position_m", o.max_position_m, "... and within this camera position, metres");
  visit("min_disagreement", o.min_disagreement,
        "... while the other lies beyond this many times a gate (> 1)");
}

}  // namespace arucoslam
