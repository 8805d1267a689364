// OrbExtractor: detects oriented FAST corners over a scale pyramid, spreads them evenly over
// each level with a quadtree and describes them with rotated BRIEF (256 bits, fixed pattern).
#pragma once

#include <opencv2/core.hpp>

#include "arucoslam/feature/brief_pattern.h"
#include "arucoslam/feature/keypoints.h"

namespace arucoslam {

struct OrbExtractorOptions {
  int num_features = 1000;          // total keypoints wanted over all levels
  int num_levels = 8;               // pyramid levels (level 0 = full image)
  double scale_factor = 1.2;        // size ratio of consecutive levels (> 1)
  int initial_fast_threshold = 20;  // FAST intensity threshold (grey levels) tried first
  int min_fast_threshold = 7;       // threshold used in grid cells where the first finds none
  int cell_size_px = 32;            // side of the grid cells for the threshold fallback (pixels)
  int edge_margin_px = 16;          // border of each level with no keypoints (>= patch radius + 1)

  bool Check() const;
};

class OrbExtractor {
 public:
  explicit OrbExtractor(const OrbExtractorOptions& options = {});

  // Features of an 8-bit single-channel image (throws std::invalid_argument otherwise).
  // `undistorted` stays empty; see feature/undistort.h.
  OrbFeatures Extract(const cv::Mat& image) const;

  const OrbExtractorOptions& options() const { return options_; }
  const ScalePyramid& pyramid() const { return pyramid_; }
  // Number of keypoints wanted at each level (proportional to the level's area).
  const std::vector<int>& features_per_level() const { return features_per_level_; }

 private:
  OrbExtractorOptions options_;
  ScalePyramid pyramid_;
  std::vector<int> features_per_level_;
  BriefPattern pattern_;
};

}  // namespace arucoslam
