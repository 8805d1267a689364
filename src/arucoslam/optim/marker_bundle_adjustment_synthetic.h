// Synthetic scenes with markers and known truth, for marker-fusion tests and benchmarks: a
// camera walking down a corridor, points in a box ahead, markers on posts facing the approach.
#pragma once

#include <cstdint>
#include <string>

#include "arucoslam/optim/marker_bundle_adjustment.h"

namespace arucoslam {

struct SyntheticMarkerSceneOptions {
  int num_poses = 20;          // cameras along world +x, z-up world, camera looking along +x
  double height_wobble_m = 0.05;  // camera height 1 m plus this times a sine along the path
  double path_length_m = 6.0;  // distance from the first to the last camera
  int num_points = 400;        // points uniformly in a box ahead of the path
  int num_markers = 4;         // markers spread from 3 m ahead of the start to past the end
  double marker_size_m = 0.3;  // side of each marker's black square
  double max_marker_distance_m = 10.0;  // markers farther from a camera are not observed
  double noise_px = 0.0;                // Gaussian noise (std dev) on keypoint pixels
  double corner_noise_px = 0.0;         // Gaussian noise (std dev) on marker corner pixels
  int image_width = 640;                // observations outside the image are dropped
  int image_height = 480;
  double focal_px = 500.0;  // fx = fy; principal point at the image centre
  std::uint32_t seed = 1;

  bool Check(std::string* why = nullptr) const;
};

// The true scene, every marker `fixed`. Observation sigmas are 1 px. Deterministic for a seed.
MarkerBundleAdjustmentProblem MakeSyntheticMarkerScene(const SyntheticMarkerSceneOptions& options);

}  // namespace arucoslam
