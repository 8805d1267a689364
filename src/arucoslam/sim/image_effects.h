// Image effects of the simulated camera that happen after rasterisation: lens distortion
// (remap of a finer pinhole render), sensor noise with a seeded generator, exposure gain.
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>

#include "arucoslam/geometry/camera.h"

namespace arucoslam {

// A pinhole camera (no distortion) that covers the field of view of a distorted camera,
// and the per-pixel maps that resample its image into the distorted camera's image.
class DistortionRemap {
 public:
  // `oversampling` (>= 1) makes the pinhole image that much finer than the output.
  // The pinhole's size is capped at 4x the output's side per axis (very wide fisheye
  // lenses lose their outer field, which is then drawn as background).
  DistortionRemap(const CameraModel& camera, double oversampling);

  // The pinhole to render (DistortionModel::kNone).
  const CameraModel& pinhole() const { return pinhole_; }
  // Resamples a pinhole render into the distorted camera's image: INTER_LINEAR for
  // intensities, INTER_NEAREST for depth (no mixing across edges). Outside: `border`.
  cv::Mat Apply(const cv::Mat& pinhole_image, int interpolation, double border = 0.0) const;

 private:
  CameraModel pinhole_;
  cv::Mat map_x_;  // CV_32FC1, output pixel -> pinhole pixel
  cv::Mat map_y_;
};

// Exposure gain at time t: gain * (1 + variation * sin(2 pi t / period)).
double ExposureGainAt(double gain, double variation, double period_s, double time_s);

// 8-bit image from a float image on the 0..255 scale (any channels) plus zero-mean
// Gaussian noise of `sigma` grey levels drawn from a generator seeded with (seed, index):
// the same inputs give the same bytes. Values are rounded and clamped to 0..255.
cv::Mat AddNoiseAndQuantize(const cv::Mat& image_0_255, double sigma, std::uint64_t seed,
                            std::uint64_t index);

}  // namespace arucoslam
