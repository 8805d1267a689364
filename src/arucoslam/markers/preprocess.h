// Image preprocessing before marker detection: grayscale, optional contrast equalisation
// (CLAHE) and optional noise reduction, configured by PreprocessOptions.
#pragma once

#include <opencv2/core.hpp>

namespace arucoslam {

enum class DenoiseMethod { kNone, kGaussian, kBilateral };

struct PreprocessOptions {
  // Contrast-limited adaptive histogram equalisation (off by default).
  bool clahe = false;
  double clahe_clip_limit = 2.0;  // contrast limit per tile (OpenCV's clipLimit), > 0
  int clahe_tile_grid = 8;        // tiles per image side, >= 1

  DenoiseMethod denoise = DenoiseMethod::kNone;
  double gaussian_sigma_px = 0.8;         // kGaussian: standard deviation, pixels, > 0
  int bilateral_diameter_px = 5;          // kBilateral: neighbourhood diameter, pixels, >= 3
  double bilateral_sigma_color = 20.0;    // kBilateral: range sigma, grey levels, > 0
  double bilateral_sigma_space_px = 3.0;  // kBilateral: spatial sigma, pixels, > 0

  bool Check(std::string* why = nullptr) const;
};

// Returns an 8-bit single-channel image: colour (BGR/BGRA) is converted to grey, 16-bit is
// scaled down, then CLAHE and denoising are applied as configured. The input is unchanged.
// Throws std::invalid_argument for an empty image or options that fail Check().
cv::Mat Preprocess(const cv::Mat& image, const PreprocessOptions& options = {});

}  // namespace arucoslam
