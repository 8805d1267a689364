// FeatureGrid: buckets the keypoints of one image by pixel position so that the features
// near a point (within a radius, in a range of pyramid levels) are found without a full scan.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "arucoslam/feature/keypoints.h"

namespace arucoslam {

class FeatureGrid {
 public:
  // `cell_size_px` is the side of one bucket in level-0 pixels (> 0). The grid copies the
  // positions and levels it needs; `features` may change or go away afterwards.
  explicit FeatureGrid(const OrbFeatures& features, double cell_size_px = 16.0);

  // Indices of the keypoints whose position is within `radius_px` of `pixel` and whose level
  // lies in [min_level, max_level] (a negative max_level means no upper bound), in grid
  // order (cell by cell, ascending within a cell; deterministic, not globally sorted).
  std::vector<int> FeaturesInRadius(const Eigen::Vector2d& pixel, double radius_px,
                                    int min_level = 0, int max_level = -1) const;

 private:
  double cell_size_;
  int cells_x_ = 0;
  int cells_y_ = 0;
  struct Entry {
    float x, y;  // keypoint position, level-0 pixels
    int level;
    int index;
  };
  std::vector<std::vector<Entry>> cells_;
};

}  // namespace arucoslam
