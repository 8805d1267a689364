#include "arucoslam/slam/synthetic_corridor.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "arucoslam/slam/synthetic_descriptors.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

constexpr int kLevels = 8;
constexpr double kLevelScale = 1.2;
constexpr double kLevel0BlobPx = 3.0;  // image size of a blob detected at level 0
constexpr double kBorderPx = 10.0;

}  // namespace

bool SyntheticCorridorOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Above("length_m", length_m, 0.0);
  check.Above("half_width_m", half_width_m, 0.0);
  check.Above("height_m", height_m, 0.0);
  check.Above("points_per_m2", points_per_m2, 0.0);
  check.Above("min_blob_m", min_blob_m, 0.0);
  check.AtLeast("max_blob_m", max_blob_m, min_blob_m);
  check.AtLeast("level0_noise_px", level0_noise_px, 0.0);
  check.InRange("detect_probability", detect_probability, 0.0, 1.0, Interval::kOpenClosed);
  return check.ok();
}

SyntheticCorridor::SyntheticCorridor(const CameraModel& camera,
                                     const SyntheticCorridorOptions& options)
    : camera_(camera), options_(options), random_(options.seed) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("SyntheticCorridorOptions: " + why);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double x0 = -5.0;
  const double length = options.length_m;
  const double w = options.half_width_m;
  const double h = options.height_m;
  auto add = [&](const Eigen::Vector3d& p) {
    points_.push_back(p);
    blob_sizes_m_.push_back(options.min_blob_m +
                            unit(random_) * (options.max_blob_m - options.min_blob_m));
    descriptors_.push_back(RandomOrbDescriptor(random_));
  };
  const int per_wall = static_cast<int>(options.points_per_m2 * length * h);
  const int per_floor = static_cast<int>(options.points_per_m2 * length * 2.0 * w);
  for (const double y : {-w, w}) {
    for (int i = 0; i < per_wall; ++i) add({x0 + unit(random_) * length, y, unit(random_) * h});
  }
  for (const double z : {0.0, h}) {
    for (int i = 0; i < per_floor; ++i) {
      add({x0 + unit(random_) * length, -w + 2.0 * w * unit(random_), z});
    }
  }
}

Frame SyntheticCorridor::MakeFrame(FrameId id, double timestamp_s, const Rigid3& cam_from_world) {
  std::normal_distribution<double> noise(0.0, options_.level0_noise_px);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double max_blob_px = kLevel0BlobPx * std::pow(kLevelScale, kLevels);
  Frame frame;
  frame.id = id;
  frame.timestamp_s = timestamp_s;
  frame.camera = camera_;
  frame.features.pyramid = ScalePyramid::Make(kLevels, kLevelScale);
  frame.features.image_width = camera_.width;
  frame.features.image_height = camera_.height;
  std::vector<int> seen;
  std::vector<cv::KeyPoint> keypoints;
  for (std::size_t j = 0; j < points_.size(); ++j) {
    const Eigen::Vector3d p_in_cam = cam_from_world * points_[j];
    if (!(p_in_cam.z() > 0.3)) continue;
    const auto pixel = camera_.Project(p_in_cam);
    if (!pixel || !camera_.InImage(*pixel, kBorderPx)) continue;
    const double blob_px = camera_.fx * blob_sizes_m_[j] / p_in_cam.z();
    if (blob_px < kLevel0BlobPx || blob_px >= max_blob_px) continue;
    if (unit(random_) >= options_.detect_probability) continue;
    const int level = std::min(
        kLevels - 1,
        static_cast<int>(std::floor(std::log(blob_px / kLevel0BlobPx) / std::log(kLevelScale))));
    const double sigma = std::pow(kLevelScale, level);
    const Eigen::Vector2d noisy = *pixel + sigma * Eigen::Vector2d(noise(random_), noise(random_));
    cv::KeyPoint keypoint(static_cast<float>(noisy.x()), static_cast<float>(noisy.y()),
                          31.0f * static_cast<float>(sigma), 0.0f);
    keypoint.octave = level;
    keypoints.push_back(keypoint);
    seen.push_back(static_cast<int>(j));
  }
  frame.features.descriptors =
      cv::Mat(static_cast<int>(keypoints.size()), kOrbDescriptorBytes, CV_8U);
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    OrbDescriptor d = descriptors_[seen[i]];
    FlipRandomBits(3, random_, &d);
    std::copy(d.begin(), d.end(), frame.features.descriptors.ptr(static_cast<int>(i)));
    frame.features.undistorted.push_back(
        camera_.Unproject(Eigen::Vector2d(keypoints[i].pt.x, keypoints[i].pt.y)));
  }
  frame.features.keypoints = std::move(keypoints);
  frame.ResetMatches();
  return frame;
}

}  // namespace arucoslam
