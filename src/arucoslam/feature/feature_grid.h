// FeatureGrid: buckets the keypoints of one image by pixel position so that the features
// near a point (within a radius, in a range of pyramid levels) are found without a full scan.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "arucoslam/feature/keypoints.h"

namespace arucoslam {

class FeatureGrid {
 public:
  // `cell_size_px` is the side of one bucket in level-0 pixels (> 0). `features` must
  // outlive the grid (it keeps a pointer).
  explicit FeatureGrid(const OrbFeatures& features, double cell_size_px = 16.0);

  // Indices of the keypoints whose position is within `radius_px` of `pixel` and whose level
  // lies in [min_level, max_level] (a negative max_level means no upper bound). Sorted.
  std::vector<int> FeaturesInRadius(const Eigen::Vector2d& pixel, double radius_px,
                                    int min_level = 0, int max_level = -1) const;

 private:
  const OrbFeatures* features_;
  double cell_size_;
  int cells_x_ = 0;
  int cells_y_ = 0;
  std::vector<std::vector<int>> cells_;
};

}  // namespace arucoslam
