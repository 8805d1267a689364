// Second-chance decoding of marker candidates that OpenCV's aruco rejected: corners refined
// to sub-pixel first, cells read by bilinear sampling near their centres, then identified.
#pragma once

#include <array>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "arucoslam/markers/edge_refiner.h"

namespace arucoslam {

struct CandidateDecoderOptions {
  int marker_border_bits = 1;  // black border width, cells
  // Cell read as the mean of samples x samples bilinear samples spread over the central
  // (1 - 2 x ignored margin) of the cell.
  int samples_per_cell = 3;
  double ignored_margin_per_cell = 0.25;  // fraction of a cell, in [0, 0.5)
  double min_contrast = 20.0;             // grey levels between the dark and bright cell means
  int max_erroneous_border_bits = 1;      // white cells tolerated in the black border
  double error_correction_rate = 0.3;     // fraction of the dictionary's capacity, [0, 1]
  // Corner refinement before reading: cv::cornerSubPix with a half window of this fraction
  // of a cell (at least 2 px); a candidate whose corner moves further than
  // max_refine_shift_cells (its place is then unsure) is dropped.
  double refine_window_cells = 0.6;      // fraction of a cell, > 0
  double max_refine_shift_cells = 0.75;  // cells, > 0
  // Corners from the four sides' edges (edge_refiner.h) first; cornerSubPix ones when those
  // fail or do not decode.
  bool edge_refinement = true;
  EdgeRefineOptions edges;
  // Cells compared with a threshold between the border's black and the quiet zone's white,
  // both fitted over the marker, after sharpening (cell += sharpening x its Laplacian over
  // the 4 neighbours); Otsu over the cells when the quiet zone is not white or that fails.
  bool ring_threshold = true;
  double sharpening = 0.25;

  bool Check(std::string* why = nullptr) const;
};

struct DecodedCandidate {
  int id = -1;
  std::array<cv::Point2f, 4> corners;  // OpenCV order (marker top-left first), clockwise
};

// Decodes one quadrilateral of `gray` (8-bit); nullopt when its bits are no marker of
// `dictionary` within the options' tolerances.
std::optional<DecodedCandidate> DecodeCandidate(const cv::Mat& gray,
                                                std::array<cv::Point2f, 4> corners,
                                                const cv::aruco::Dictionary& dictionary,
                                                const CandidateDecoderOptions& options);

}  // namespace arucoslam
