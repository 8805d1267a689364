// OrbFeatures and ScalePyramid: the keypoints and 256-bit descriptors of one image, as the
// extractor returns them and as matching, map and tracking code consume them.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace arucoslam {

// Length of one ORB descriptor in bytes (256 bits).
inline constexpr int kOrbDescriptorBytes = 32;

// Scale factors of an image pyramid. Level 0 is the full-resolution image; a pixel of level
// l covers scales[l] x scales[l] pixels of level 0 (scales[l] = scale_factor^l).
struct ScalePyramid {
  int num_levels = 8;
  double scale_factor = 1.2;
  std::vector<double> scales;          // scale_factor^l, l = 0..num_levels-1
  std::vector<double> inverse_scales;  // 1 / scales[l]
  std::vector<double> sigma2;          // scales[l]^2: keypoint variance (px^2) at level l
  std::vector<double> inverse_sigma2;  // 1 / sigma2[l]

  // Fills the tables for `num_levels` levels of ratio `scale_factor` (> 1).
  static ScalePyramid Make(int num_levels, double scale_factor);

  // Level at which a point seen at `distance` (any unit) would appear, given that it was
  // observed at `reference_level` from `reference_distance`; clamped to [0, num_levels-1].
  int PredictLevel(double distance, double reference_distance, int reference_level) const;
};

// The features of one image. Index i refers to the same feature in every vector/row.
struct OrbFeatures {
  // Positions in level-0 pixels of the image as captured (distorted); `octave` is the
  // pyramid level, `angle` the orientation in degrees [0, 360) (image x right, y down),
  // `size` the patch diameter in level-0 pixels, `response` the FAST score.
  std::vector<cv::KeyPoint> keypoints;
  // keypoints.size() x 32, CV_8U: one rotated-BRIEF descriptor per row.
  cv::Mat descriptors;
  // Undistorted NORMALISED image coordinates (x/z, y/z in the camera frame, no intrinsics),
  // from CameraModel::Unproject; empty until UndistortFeatures() (feature/undistort.h) runs.
  std::vector<Eigen::Vector2d> undistorted;
  ScalePyramid pyramid;
  int image_width = 0;
  int image_height = 0;

  std::size_t size() const { return keypoints.size(); }
  bool empty() const { return keypoints.empty(); }
  const std::uint8_t* Descriptor(int index) const { return descriptors.ptr<std::uint8_t>(index); }
};

}  // namespace arucoslam
