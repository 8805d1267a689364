// Synthetic test images: generated marker PNGs warped into a pinhole camera's image at
// known poses, over a uniform or textured background, with optical blur and sensor noise.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

struct SyntheticMarker {
  std::string dictionary = "DICT_4X4_50";
  int id = 0;
  double size = 0.2;              // side of the black square, metres
  double quiet_zone_cells = 2.0;  // white margin printed around it, marker cells
  Rigid3 cam_from_marker;         // marker frame: OpenCV aruco (z out of the printed face)
  double white_level = 220.0;     // grey level of the paper, 0..255
  double black_level = 25.0;      // grey level of the ink, 0..255
};

enum class SyntheticBackground { kUniform, kTextured };

struct SyntheticViewOptions {
  SyntheticBackground background = SyntheticBackground::kTextured;
  double background_mean = 128.0;  // mean grey level of the background, 0..255
  double texture_contrast = 40.0;  // kTextured: standard deviation of the texture, grey levels
  double blur_sigma_px = 0.7;      // Gaussian optical blur, pixels (0: none)
  double noise_sigma = 3.0;        // additive Gaussian sensor noise, grey levels (0: none)
  int supersampling = 3;           // sub-pixels per pixel side when warping, >= 1
  std::uint64_t seed = 1;          // texture and noise are deterministic from the seed

  bool Check(std::string* why = nullptr) const;
};

// The pinhole camera of the synthetic marker tests: 640x480, fx = fy = 500, principal point
// at the image centre, no distortion.
CameraModel SyntheticCamera640();

// Renders an 8-bit grey image of camera.width x camera.height. The camera must be a
// pinhole without distortion (DistortionModel::kNone); markers with any part behind the
// camera are skipped. Throws std::invalid_argument on bad options or a distorted camera.
cv::Mat RenderSyntheticView(const CameraModel& camera, const std::vector<SyntheticMarker>& markers,
                            const SyntheticViewOptions& options = {});

// `image` compressed as JPEG at `quality` (0-100) and decoded to grey: the blocking and ringing
// of a camera's compression.
cv::Mat ThroughJpeg(const cv::Mat& image, int quality);

// The true pixel positions of a marker's black-square corners (OpenCV order), pinhole.
std::array<Eigen::Vector2d, 4> ProjectMarkerCorners(const CameraModel& camera,
                                                    const SyntheticMarker& marker);

}  // namespace arucoslam
