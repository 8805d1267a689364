#include "arucoslam/feature/feature_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace arucoslam {

FeatureGrid::FeatureGrid(const OrbFeatures& features, double cell_size_px)
    : cell_size_(cell_size_px) {
  if (!(cell_size_px > 0.0)) throw std::invalid_argument("FeatureGrid: cell size must be > 0");
  double max_x = features.image_width, max_y = features.image_height;
  for (const cv::KeyPoint& kp : features.keypoints) {
    max_x = std::max(max_x, static_cast<double>(kp.pt.x) + 1.0);
    max_y = std::max(max_y, static_cast<double>(kp.pt.y) + 1.0);
  }
  cells_x_ = std::max(1, static_cast<int>(std::ceil(max_x / cell_size_)));
  cells_y_ = std::max(1, static_cast<int>(std::ceil(max_y / cell_size_)));
  cells_.resize(static_cast<std::size_t>(cells_x_) * cells_y_);
  for (int i = 0; i < static_cast<int>(features.keypoints.size()); ++i) {
    const cv::Point2f& p = features.keypoints[i].pt;
    const int cx = std::clamp(static_cast<int>(std::floor(p.x / cell_size_)), 0, cells_x_ - 1);
    const int cy = std::clamp(static_cast<int>(std::floor(p.y / cell_size_)), 0, cells_y_ - 1);
    cells_[cy * cells_x_ + cx].push_back({p.x, p.y, features.keypoints[i].octave, i});
  }
}

std::vector<int> FeatureGrid::FeaturesInRadius(const Eigen::Vector2d& pixel, double radius_px,
                                               int min_level, int max_level) const {
  std::vector<int> found;
  if (!(radius_px >= 0.0) || !pixel.allFinite()) return found;
  const int x0 = std::max(0, static_cast<int>(std::floor((pixel.x() - radius_px) / cell_size_)));
  const int x1 =
      std::min(cells_x_ - 1, static_cast<int>(std::floor((pixel.x() + radius_px) / cell_size_)));
  const int y0 = std::max(0, static_cast<int>(std::floor((pixel.y() - radius_px) / cell_size_)));
  const int y1 =
      std::min(cells_y_ - 1, static_cast<int>(std::floor((pixel.y() + radius_px) / cell_size_)));
  const double radius2 = radius_px * radius_px;
  for (int cy = y0; cy <= y1; ++cy) {
    for (int cx = x0; cx <= x1; ++cx) {
      for (const Entry& entry : cells_[cy * cells_x_ + cx]) {
        if (entry.level < min_level || (max_level >= 0 && entry.level > max_level)) continue;
        const double dx = entry.x - pixel.x(), dy = entry.y - pixel.y();
        if (dx * dx + dy * dy <= radius2) found.push_back(entry.index);
      }
    }
  }
  return found;
}

}  // namespace arucoslam
