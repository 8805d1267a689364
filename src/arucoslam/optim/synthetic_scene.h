// Synthetic bundle-adjustment scenes with known truth, for tests and benchmarks: cameras on
// a line looking at a box of points, observations projected exactly or with pixel noise.
#pragma once

#include <cstdint>
#include <string>

#include "arucoslam/optim/bundle_adjustment.h"

namespace arucoslam {

struct SyntheticSceneOptions {
  int num_poses = 10;        // cameras, spaced `baseline_m` apart along world x
  int num_points = 1000;     // points drawn uniformly in a box in front of the cameras
  double baseline_m = 0.3;   // distance between consecutive cameras, metres
  double min_depth_m = 3.0;  // box of points: depth range in front of the first camera
  double max_depth_m = 8.0;
  double noise_px = 0.0;  // Gaussian pixel noise (standard deviation) on observations
  int image_width = 640;  // observations outside the image are dropped
  int image_height = 480;
  double focal_px = 500.0;  // fx = fy; principal point at the image centre
  std::uint32_t seed = 1;

  bool Check(std::string* why = nullptr) const;
};

// The true scene: poses and points exact, observations with `noise_px` Gaussian noise and
// sigma_px = 1, so whitened residuals are pixel residuals. Deterministic for a seed.
BundleAdjustmentProblem MakeSyntheticScene(const SyntheticSceneOptions& options);

}  // namespace arucoslam
