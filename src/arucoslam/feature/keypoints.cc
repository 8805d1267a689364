#include "arucoslam/feature/keypoints.h"

#include <algorithm>
#include <cmath>

namespace arucoslam {

ScalePyramid ScalePyramid::Make(int num_levels, double scale_factor) {
  ScalePyramid pyramid;
  pyramid.num_levels = num_levels;
  pyramid.scale_factor = scale_factor;
  double scale = 1.0;
  for (int level = 0; level < num_levels; ++level) {
    pyramid.scales.push_back(scale);
    pyramid.inverse_scales.push_back(1.0 / scale);
    pyramid.sigma2.push_back(scale * scale);
    pyramid.inverse_sigma2.push_back(1.0 / (scale * scale));
    scale *= scale_factor;
  }
  return pyramid;
}

int ScalePyramid::PredictLevel(double distance, double reference_distance,
                               int reference_level) const {
  if (num_levels <= 1 || distance <= 0.0 || reference_distance <= 0.0) {
    return std::clamp(reference_level, 0, std::max(0, num_levels - 1));
  }
  // Apparent size scales with 1/distance: closer -> finer detail -> higher level.
  const double ratio = reference_distance / distance;
  const double level = reference_level + std::log(ratio) / std::log(scale_factor);
  return std::clamp(static_cast<int>(std::lround(level)), 0, num_levels - 1);
}

}  // namespace arucoslam
