#include "arucoslam/map/map_point.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "arucoslam/feature/orb_matcher.h"

namespace arucoslam {

int MapPoint::PredictLevel(double distance, const ScalePyramid& pyramid) const {
  if (distance <= 0.0 || max_distance <= 0.0 || pyramid.num_levels <= 1) return 0;
  // At max_distance the point appears at level 0.
  const double level =
      std::ceil(std::log(max_distance / distance) / std::log(pyramid.scale_factor));
  return std::clamp(static_cast<int>(level), 0, pyramid.num_levels - 1);
}

int MedianDescriptorIndex(const std::vector<const std::uint8_t*>& descriptors) {
  const int n = static_cast<int>(descriptors.size());
  if (n == 0) return -1;
  std::vector<std::vector<int>> distances(n, std::vector<int>(n, 0));
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      distances[i][j] = distances[j][i] = HammingDistance(descriptors[i], descriptors[j]);
    }
  }
  int best_index = 0;
  int best_median = std::numeric_limits<int>::max();
  for (int i = 0; i < n; ++i) {
    std::vector<int> row = distances[i];
    std::nth_element(row.begin(), row.begin() + (n - 1) / 2, row.end());
    const int median = row[(n - 1) / 2];
    if (median < best_median) {
      best_median = median;
      best_index = i;
    }
  }
  return best_index;
}

}  // namespace arucoslam
