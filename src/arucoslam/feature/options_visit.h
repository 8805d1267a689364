// VisitOptions for the feature layer's options structs: each field once, with its comment
// (the protocol: util/options_visit.h). Config files are read and written from these.
#pragma once

#include "arucoslam/feature/orb_extractor.h"
#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/util/options_visit.h"

namespace arucoslam {

template <class Visitor>
void VisitOptions(OrbExtractorOptions& o, Visitor& visit) {
  visit("num_features", o.num_features, "total keypoints wanted over all levels");
  visit("num_levels", o.num_levels, "pyramid levels (level 0: the full image)");
  visit("scale_factor", o.scale_factor, "size ratio of consecutive levels (> 1)");
  visit("initial_fast_threshold", o.initial_fast_threshold,
        "FAST intensity threshold tried first, grey levels");
  visit("min_fast_threshold", o.min_fast_threshold,
        "FAST threshold in grid cells where the first finds nothing, grey levels");
  visit("cell_size_px", o.cell_size_px, "side of the grid cells of that fallback, pixels");
  visit("edge_margin_px", o.edge_margin_px, "border of each level with no keypoints, pixels");
  visit("num_threads", o.num_threads,
        "threads building and describing the levels, the caller included (same output)");
}

template <class Visitor>
void VisitOptions(RotationCheckOptions& o, Visitor& visit) {
  visit("histogram_bins", o.histogram_bins, "bins over 360 degrees of keypoint-angle difference");
  visit("keep_bins", o.keep_bins, "the most populated bins kept");
  visit("min_fraction_of_best", o.min_fraction_of_best,
        "a kept bin other than the fullest holds at least this fraction of it");
}

template <class Visitor>
void VisitOptions(WindowMatchOptions& o, Visitor& visit) {
  visit("window_radius_px", o.window_radius_px,
        "search radius around the predicted position, pixels");
  visit("max_level_difference", o.max_level_difference, "pyramid levels apart at most");
  visit("max_distance", o.max_distance, "descriptor distance at most, bits");
  visit("ratio", o.ratio, "best < ratio x second best");
  visit("check_rotation", o.check_rotation, "drop matches off the dominant rotation");
  visit("rotation", o.rotation, "the rotation-consistency filter");
}

template <class Visitor>
void VisitOptions(ProjectionMatchOptions& o, Visitor& visit) {
  visit("base_radius_px", o.base_radius_px,
        "search radius = this x the caller's factor x scale(level), level-0 pixels");
  visit("level_tolerance", o.level_tolerance, "candidates at the predicted level +- this");
  visit("max_distance", o.max_distance, "descriptor distance at most, bits");
  visit("ratio", o.ratio, "best < ratio x second best when both are at the same level");
  visit("check_rotation", o.check_rotation, "drop matches off the dominant rotation");
  visit("rotation", o.rotation, "the rotation-consistency filter");
}

template <class Visitor>
void VisitOptions(BruteForceMatchOptions& o, Visitor& visit) {
  visit("max_distance", o.max_distance, "a best match farther than this is dropped, bits");
  visit("ratio", o.ratio, "best < ratio x second best (1: no ratio test)");
  visit("cross_check", o.cross_check, "keep only mutual best matches");
  visit("check_rotation", o.check_rotation, "drop matches off the dominant rotation");
  visit("rotation", o.rotation, "the rotation-consistency filter");
}

}  // namespace arucoslam
