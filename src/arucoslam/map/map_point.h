// MapPoint: a 3D point of the map with its observations (keyframe -> keypoint index), a
// representative descriptor, viewing direction and the distance range for scale prediction.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>

#include "arucoslam/feature/keypoints.h"
#include "arucoslam/map/ids.h"

namespace arucoslam {

using OrbDescriptor = std::array<std::uint8_t, kOrbDescriptorBytes>;

struct MapPoint {
  MapPointId id;  // assigned by Map
  Eigen::Vector3d p_in_world = Eigen::Vector3d::Zero();
  // The observation whose descriptor has the least median Hamming distance to the others.
  OrbDescriptor descriptor{};
  // Keyframe -> index of the keypoint that observes this point; kept by the Map.
  std::map<KeyframeId, int> observations;
  KeyframeId reference_keyframe;  // the keyframe that created it
  // Mean unit viewing direction (camera centre -> point) over the observations.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  // Distances (metres) at which the point can be matched across the pyramid: seen at level l
  // from distance d by the reference keyframe, max = d * scale(l), min = max / scale(top).
  double min_distance = 0.0;
  double max_distance = 0.0;
  // Tracking statistics: frames where it was predicted visible / actually matched.
  int num_visible = 1;
  int num_found = 1;

  int NumObservations() const { return static_cast<int>(observations.size()); }
  double FoundRatio() const {
    return num_visible > 0 ? static_cast<double>(num_found) / num_visible : 0.0;
  }
  // Pyramid level at which the point should appear from `distance` metres away.
  int PredictLevel(double distance, const ScalePyramid& pyramid) const;
  // Whether `distance` lies in the matchable range (with ORB-SLAM's 0.8 / 1.2 slack).
  bool InDistanceRange(double distance) const {
    return distance >= 0.8 * min_distance && distance <= 1.2 * max_distance;
  }
};

// Index of the descriptor with the least median Hamming distance to all others (0 for
// one descriptor; -1 for none). Rows are 32-byte descriptors.
int MedianDescriptorIndex(const std::vector<const std::uint8_t*>& descriptors);

}  // namespace arucoslam
