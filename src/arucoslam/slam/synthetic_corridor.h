// SyntheticCorridor: keypoints on the walls, floor and ceiling of a long straight corridor,
// each seen at the pyramid level its size in the image gives, with unbiased Gaussian noise
// scaled by that level; for tests of how the keypoint SLAM keeps its scale without images.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "arucoslam/map/frame.h"
#include "arucoslam/map/map_point.h"

namespace arucoslam {

struct SyntheticCorridorOptions {
  double length_m = 60.0;       // along world x, from -5 m
  double half_width_m = 2.0;    // walls at y = +-half_width_m
  double height_m = 3.0;        // floor z = 0, ceiling z = height_m
  double points_per_m2 = 10.0;  // texture density on every surface
  double min_blob_m = 0.01;     // texture blob sizes, uniform in [min, max]
  double max_blob_m = 0.10;
  double level0_noise_px = 0.5;     // keypoint noise at level 0 (std); x 1.2^level above
  double detect_probability = 0.7;  // each visible blob is detected in a frame with this
  std::uint32_t seed = 1;

  bool Check(std::string* why = nullptr) const;
};

class SyntheticCorridor {
 public:
  SyntheticCorridor(const CameraModel& camera, const SyntheticCorridorOptions& options = {});

  // The frame seen from `cam_from_world`: blobs in front of the camera, 10 px inside the
  // image, whose image size lies in the pyramid's range (3 px at level 0 to 3 x 1.2^8 px),
  // detected with the detect probability; `undistorted` filled, matches reset.
  Frame MakeFrame(FrameId id, double timestamp_s, const Rigid3& cam_from_world);

  std::size_t num_points() const { return points_.size(); }

 private:
  CameraModel camera_;
  SyntheticCorridorOptions options_;
  std::mt19937 random_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<double> blob_sizes_m_;
  std::vector<OrbDescriptor> descriptors_;
};

}  // namespace arucoslam
