// SyntheticFeatureScene: frames of keypoints with descriptors seen by a pinhole camera in a
// random point cloud, with known truth, for tests of tracking, mapping and the pipeline.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "arucoslam/map/frame.h"
#include "arucoslam/map/map_point.h"

namespace arucoslam {

struct SyntheticFeatureOptions {
  int num_points = 1200;
  Eigen::Vector3d box_min{-4.0, -3.0, 4.0};  // world box the points fill, metres
  Eigen::Vector3d box_max{6.0, 3.0, 10.0};
  double pixel_noise = 0.3;  // keypoint noise, pixels (std)
  int flipped_bits = 3;      // descriptor bits flipped per observation
  int num_distractors = 100;  // keypoints with random descriptors per frame
  double border_px = 20.0;    // points closer than this to the image border are not seen
  std::uint32_t seed = 1;

  bool Check(std::string* why = nullptr) const;
};

class SyntheticFeatureScene {
 public:
  SyntheticFeatureScene(const CameraModel& camera, const SyntheticFeatureOptions& options = {});

  // The frame seen from `cam_from_world` (features at level 0, angle 0, `undistorted`
  // filled, matches reset, pose left empty); truth[i] is keypoint i's point index, -1 for a
  // distractor.
  Frame MakeFrame(FrameId id, double timestamp_s, const Rigid3& cam_from_world,
                  std::vector<int>* truth);

  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  const CameraModel& camera() const { return camera_; }

 private:
  OrbDescriptor RandomDescriptor();

  CameraModel camera_;
  SyntheticFeatureOptions options_;
  std::mt19937 random_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<OrbDescriptor> descriptors_;
};

}  // namespace arucoslam
