// Sub-pixel quad corners from a local threshold, as a binarising tag detector (AprilTag)
// places them: the grey level is thresholded midway between the darkest and brightest pixel
// around (over tiles), the crossings of that threshold between neighbouring pixels are
// located by interpolation, and each side is a line fitted to the dark-to-bright crossings
// along it, weighted by the gradient.
#pragma once

#include <array>
#include <opencv2/core.hpp>

namespace arucoslam {

struct ThresholdLineFitOptions {
  // The threshold of a pixel is the mean of the lowest and highest grey level over the 3 x 3
  // tiles around its own tile (tiles of tile_px, aligned with the image's origin); where
  // they differ by less than min_contrast, the pixel is neither dark nor bright.
  int tile_px = 4;
  double min_contrast = 5.0;
  // A crossing belongs to a side within band_cells of a cell across the marker (the
  // marker's width at that side / cells) of its line, clamped to [min_band_px, max_band_px].
  double band_cells = 0.6;
  double min_band_px = 0.75;
  double max_band_px = 3.0;
  int iterations = 3;  // crossings are re-assigned to the refitted lines
  int min_points_per_side = 3;
  double max_shift_cells = 0.75;  // a corner moving further fails the fit

  bool Check(std::string* why = nullptr) const;
};

// `corners` in either winding, `cells` cells across (border included); pixel centres at
// integer coordinates. Returns false (corners unchanged) when a side has too few crossings
// or a corner moves too far.
bool FitQuadToThreshold(const cv::Mat& gray, int cells, const ThresholdLineFitOptions& options,
                        std::array<cv::Point2f, 4>& corners);

}  // namespace arucoslam
