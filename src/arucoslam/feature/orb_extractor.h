// OrbExtractor: detects oriented FAST corners over a scale pyramid, spreads them evenly over
// each level with a quadtree and describes them with rotated BRIEF (256 bits, fixed pattern).
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "arucoslam/feature/brief_pattern.h"
#include "arucoslam/feature/keypoints.h"
#include "arucoslam/util/thread_pool.h"

namespace arucoslam {

struct OrbExtractorOptions {
  int num_features = 1000;          // total keypoints wanted over all levels
  int num_levels = 8;               // pyramid levels (level 0 = full image)
  double scale_factor = 1.2;        // size ratio of consecutive levels (> 1)
  int initial_fast_threshold = 20;  // FAST intensity threshold (grey levels) tried first
  int min_fast_threshold = 7;       // threshold used in grid cells where the first finds none
  int cell_size_px = 32;            // side of the grid cells for the threshold fallback (pixels)
  int edge_margin_px = 16;          // border of each level with no keypoints (>= patch radius + 1)
  // Threads that build, detect and describe the pyramid levels (the calling thread counts as
  // one; 1 = no thread of the extractor's own). The output is the same for any count. 2 is
  // faster alone on two cores but slower in a `run` sharing them (BENCHMARKS.md).
  int num_threads = 1;

  bool Check(std::string* why = nullptr) const;
};

class OrbExtractor {
 public:
  explicit OrbExtractor(const OrbExtractorOptions& options = {});
  ~OrbExtractor();
  OrbExtractor(OrbExtractor&&) noexcept;
  OrbExtractor& operator=(OrbExtractor&&) noexcept;

  // Features of an 8-bit single-channel image (throws std::invalid_argument otherwise).
  // `undistorted` stays empty; see feature/undistort.h. Calls from several threads are
  // safe; with num_threads > 1 they take turns on the extractor's threads.
  OrbFeatures Extract(const cv::Mat& image) const;

  const OrbExtractorOptions& options() const { return options_; }
  const ScalePyramid& pyramid() const { return pyramid_; }
  // Number of keypoints wanted at each level (proportional to the level's area).
  const std::vector<int>& features_per_level() const { return features_per_level_; }

 private:
  struct LevelFeatures {
    std::vector<cv::KeyPoint> keypoints;  // in level-0 pixels
    cv::Mat descriptors;                  // one row per keypoint
  };
  // Keypoints and descriptors of one level's image; `image_size` is level 0's.
  LevelFeatures ExtractLevel(const cv::Mat& level_image, int level, cv::Size image_size) const;

  OrbExtractorOptions options_;
  ScalePyramid pyramid_;
  std::vector<int> features_per_level_;
  BriefPattern pattern_;
  std::unique_ptr<ThreadPool> pool_;  // null when num_threads == 1
};

}  // namespace arucoslam
