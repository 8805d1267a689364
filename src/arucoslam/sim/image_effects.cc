#include "arucoslam/sim/image_effects.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace arucoslam {

DistortionRemap::DistortionRemap(const CameraModel& camera, double oversampling) {
  oversampling = std::max(1.0, oversampling);
  // Field of view: the undistorted directions of the output image's border pixels.
  double min_x = 0.0, max_x = 0.0, min_y = 0.0, max_y = 0.0;
  bool first = true;
  auto include = [&](double u, double v) {
    const Eigen::Vector2d n = camera.Unproject(Eigen::Vector2d(u, v));
    if (!n.allFinite()) return;
    if (first) {
      min_x = max_x = n.x();
      min_y = max_y = n.y();
      first = false;
    }
    min_x = std::min(min_x, n.x());
    max_x = std::max(max_x, n.x());
    min_y = std::min(min_y, n.y());
    max_y = std::max(max_y, n.y());
  };
  const double right = camera.width - 0.5, bottom = camera.height - 0.5;
  for (double u = -0.5; u <= right; u += 1.0) {
    include(u, -0.5);
    include(u, bottom);
  }
  for (double v = -0.5; v <= bottom; v += 1.0) {
    include(-0.5, v);
    include(right, v);
  }
  // Keep the pinhole within 4x the output size (a wide fisheye would otherwise explode).
  const double fx = camera.fx * oversampling, fy = camera.fy * oversampling;
  const double limit_x = 2.0 * camera.width * oversampling / fx;   // half-width 4x / 2
  const double limit_y = 2.0 * camera.height * oversampling / fy;
  min_x = std::max(min_x, -limit_x);
  max_x = std::min(max_x, limit_x);
  min_y = std::max(min_y, -limit_y);
  max_y = std::min(max_y, limit_y);
  pinhole_ = camera;
  pinhole_.model = DistortionModel::kNone;
  pinhole_.distortion = {};
  pinhole_.fx = fx;
  pinhole_.fy = fy;
  // One pixel of margin on each side for the bilinear lookups.
  pinhole_.cx = -min_x * fx + 1.5;
  pinhole_.cy = -min_y * fy + 1.5;
  pinhole_.width = static_cast<int>(std::ceil((max_x - min_x) * fx)) + 3;
  pinhole_.height = static_cast<int>(std::ceil((max_y - min_y) * fy)) + 3;

  map_x_.create(camera.height, camera.width, CV_32FC1);
  map_y_.create(camera.height, camera.width, CV_32FC1);
  for (int v = 0; v < camera.height; ++v) {
    float* row_x = map_x_.ptr<float>(v);
    float* row_y = map_y_.ptr<float>(v);
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector2d n = camera.Unproject(Eigen::Vector2d(u, v));
      row_x[u] = static_cast<float>(fx * n.x() + pinhole_.cx);
      row_y[u] = static_cast<float>(fy * n.y() + pinhole_.cy);
    }
  }
}

cv::Mat DistortionRemap::Apply(const cv::Mat& pinhole_image, int interpolation,
                               double border) const {
  cv::Mat output;
  cv::remap(pinhole_image, output, map_x_, map_y_, interpolation, cv::BORDER_CONSTANT,
            cv::Scalar::all(border));
  return output;
}

double ExposureGainAt(double gain, double variation, double period_s, double time_s) {
  return gain * (1.0 + variation * std::sin(2.0 * std::numbers::pi * time_s / period_s));
}

cv::Mat AddNoiseAndQuantize(const cv::Mat& image_0_255, double sigma, std::uint64_t seed,
                            std::uint64_t index) {
  cv::Mat image;
  image_0_255.convertTo(image, CV_MAKETYPE(CV_32F, image_0_255.channels()));
  if (sigma > 0.0) {
    // cv::RNG is a fixed multiply-with-carry generator: the same on every platform.
    cv::RNG rng(seed * 0x9E3779B97F4A7C15ull + index * 0xBF58476D1CE4E5B9ull + 1);
    cv::Mat noise(image.size(), image.type());
    rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
    image += noise;
  }
  cv::Mat output;
  image.convertTo(output, CV_MAKETYPE(CV_8U, image.channels()));  // rounds and saturates
  return output;
}

}  // namespace arucoslam
