// Sub-pixel corners of a dark quadrilateral on a brighter surround from its four sides: each
// side's edge points are found across it, a line is fitted to them, neighbours intersect.
#pragma once

#include <array>
#include <opencv2/core.hpp>

#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct EdgeRefineOptions {
  // Edge points are searched along the side's normal up to this distance from the current
  // side, in cells of the marker (the border is one cell wide: keep it under 1).
  double search_cells = 0.7;
  int iterations = 2;
  // A side keeps its refit only with at least this fraction of its samples on an edge.
  double min_edge_fraction = 0.5;
  // An edge point needs a dark-to-bright step of at least this many grey levels over 2 px.
  double min_step = 12.0;
  double max_shift_cells = 0.75;  // a corner moving further fails the refinement
  // Half width of the difference that gives the grey profile's derivative, pixels. 1 steadies
  // it on noisy JPEG photos; 0.5 locates the edge of a small sharp marker better (rendered
  // markers of 15-30 px: 0.05-0.07 px RMS corner error against 0.06-0.11 px with 1).
  double derivative_half_width_px = 1.0;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Above("search_cells", search_cells, 0.0);
    check.Above("derivative_half_width_px", derivative_half_width_px, 0.0);
    check.AtLeast("iterations", iterations, 1);
    check.InRange("min_edge_fraction", min_edge_fraction, 0.0, 1.0, Interval::kClosed);
    check.AtLeast("min_step", min_step, 0.0);
    check.Above("max_shift_cells", max_shift_cells, 0.0);
    return check.ok();
  }
};

// `corners`: clockwise on screen (y down), `cells` cells across the quadrilateral. Returns
// false (corners unchanged) when a side has too few edge points or a corner moves too far.
bool RefineQuadEdges(const cv::Mat& gray, int cells, const EdgeRefineOptions& options,
                     std::array<cv::Point2f, 4>& corners);

}  // namespace arucoslam
