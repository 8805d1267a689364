#include "arucoslam/markers/synthetic_view.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "arucoslam/markers/dictionary.h"
#include "arucoslam/markers/marker_image.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool SyntheticViewOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.InRange("background_mean", background_mean, 0.0, 255.0, Interval::kClosed);
  check.AtLeast("texture_contrast", texture_contrast, 0.0);
  check.AtLeast("blur_sigma_px", blur_sigma_px, 0.0);
  check.AtLeast("noise_sigma", noise_sigma, 0.0);
  check.InRange("supersampling", supersampling, 1, 8, Interval::kClosed);
  return check.ok();
}

namespace {

Eigen::Matrix3d Intrinsics(const CameraModel& camera) {
  Eigen::Matrix3d k;
  k << camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0;
  return k;
}

cv::Mat TexturedBackground(const cv::Size& size, const SyntheticViewOptions& options,
                           cv::RNG& rng) {
  cv::Mat texture(size, CV_32F, cv::Scalar(0.0));
  // Value noise at three scales plus a few hard-edged shapes (edges that look like corners).
  for (const int cell : {64, 16, 4}) {
    cv::Mat coarse(size.height / cell + 3, size.width / cell + 3, CV_32F);
    rng.fill(coarse, cv::RNG::NORMAL, 0.0, 1.0);
    cv::Mat fine;
    cv::resize(coarse, fine, cv::Size(coarse.cols * cell, coarse.rows * cell), 0, 0,
               cv::INTER_CUBIC);
    texture += fine(cv::Rect(cell, cell, size.width, size.height)) * (cell >= 16 ? 1.0 : 0.5);
  }
  for (int i = 0; i < 12; ++i) {
    const cv::Point a(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const cv::Point b(a.x + rng.uniform(-120, 120), a.y + rng.uniform(-120, 120));
    const double value = rng.gaussian(1.2);
    if (i % 2 == 0) {
      cv::rectangle(texture, a, b, cv::Scalar(value), cv::FILLED);
    } else {
      cv::line(texture, a, b, cv::Scalar(value), rng.uniform(1, 6));
    }
  }
  cv::Scalar mean, stddev;
  cv::meanStdDev(texture, mean, stddev);
  texture = (texture - mean[0]) * (options.texture_contrast / std::max(stddev[0], 1e-9)) +
            options.background_mean;
  return texture;
}

// Composites one marker onto `image` (CV_32F, grey levels) by supersampled warping.
void DrawMarker(const CameraModel& camera, const SyntheticMarker& marker, int supersampling,
                cv::Mat& image) {
  const double half = 0.5 * marker.size;
  const double margin = marker.quiet_zone_cells * marker.size /
                        (DictionaryFromName(marker.dictionary)->markerSize + 2);
  // Outline of the printed square (margin included), in pixels, for the bounding box.
  std::vector<cv::Point2f> outline;
  for (const Eigen::Vector2d& xy : {Eigen::Vector2d(-1, 1), Eigen::Vector2d(1, 1),
                                    Eigen::Vector2d(1, -1), Eigen::Vector2d(-1, -1)}) {
    const Eigen::Vector3d p =
        marker.cam_from_marker *
        Eigen::Vector3d(xy.x() * (half + margin), xy.y() * (half + margin), 0.0);
    if (p.z() <= 1e-6) return;
    outline.emplace_back(camera.fx * p.x() / p.z() + camera.cx,
                         camera.fy * p.y() / p.z() + camera.cy);
  }
  cv::Rect box = cv::boundingRect(outline);
  box = cv::Rect(box.x - 2, box.y - 2, box.width + 4, box.height + 4) &
        cv::Rect(0, 0, image.cols, image.rows);
  if (box.area() == 0) return;

  // Source image at a resolution about twice the projected one (avoids aliasing).
  const int cells = DictionaryFromName(marker.dictionary)->markerSize + 2;
  const double projected_side = supersampling * cv::arcLength(outline, true) / 4.0;
  const int per_cell =
      std::clamp(static_cast<int>(std::ceil(2.0 * projected_side / cells)), 4, 200);
  MarkerImageOptions image_options;
  image_options.marker_size_px = cells * per_cell;
  image_options.quiet_zone_cells = marker.quiet_zone_cells;
  const cv::Mat source8 = DrawMarkerImage(marker.dictionary, marker.id, image_options);
  const double q = QuietZonePixels(marker.dictionary, image_options);
  const double marker_px = image_options.marker_size_px;
  cv::Mat source;
  source8.convertTo(source, CV_32F, (marker.white_level - marker.black_level) / 255.0,
                    marker.black_level);
  // Point-sampling a hard edge quantises it to 1/supersampling px; a blur of one sub-pixel
  // on the source turns edges into ramps whose sampled position is continuous (unbiased).
  const double source_per_sub = source.cols / std::max(1.0, projected_side);
  cv::GaussianBlur(source, source, cv::Size(0, 0), std::max(0.5, source_per_sub));

  // source pixel (u, v) -> marker plane (X, Y) -> camera -> pixel -> sub-pixel in the box.
  Eigen::Matrix3d plane_from_source;
  plane_from_source << marker.size / marker_px, 0.0, -half - (q - 0.5) * marker.size / marker_px,
      0.0, -marker.size / marker_px, half + (q - 0.5) * marker.size / marker_px, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d r = marker.cam_from_marker.RotationMatrix();
  Eigen::Matrix3d cam_from_plane;
  cam_from_plane << r.col(0), r.col(1), marker.cam_from_marker.translation;
  const double s = supersampling;
  Eigen::Matrix3d sub_from_pixel;
  sub_from_pixel << s, 0.0, s * (0.5 - box.x) - 0.5, 0.0, s, s * (0.5 - box.y) - 0.5, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d h =
      sub_from_pixel * Intrinsics(camera) * cam_from_plane * plane_from_source;
  cv::Mat h_cv(3, 3, CV_64F);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) h_cv.at<double>(i, j) = h(i, j);

  const cv::Size sub_size(box.width * supersampling, box.height * supersampling);
  cv::Mat warped, coverage;
  cv::warpPerspective(source, warped, h_cv, sub_size, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
  cv::warpPerspective(cv::Mat(source.size(), CV_32F, cv::Scalar(1.0)), coverage, h_cv, sub_size,
                      cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
  cv::Mat warped_small, coverage_small;
  cv::resize(warped, warped_small, box.size(), 0, 0, cv::INTER_AREA);
  cv::resize(coverage, coverage_small, box.size(), 0, 0, cv::INTER_AREA);
  cv::Mat roi = image(box);
  roi = roi.mul(1.0 - coverage_small) + warped_small;
}

}  // namespace

std::array<Eigen::Vector2d, 4> ProjectMarkerCorners(const CameraModel& camera,
                                                    const SyntheticMarker& marker) {
  const double half = 0.5 * marker.size;
  const std::array<Eigen::Vector3d, 4> in_marker = {
      Eigen::Vector3d(-half, half, 0), Eigen::Vector3d(half, half, 0),
      Eigen::Vector3d(half, -half, 0), Eigen::Vector3d(-half, -half, 0)};
  std::array<Eigen::Vector2d, 4> pixels;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d p = marker.cam_from_marker * in_marker[i];
    pixels[i] = {camera.fx * p.x() / p.z() + camera.cx, camera.fy * p.y() / p.z() + camera.cy};
  }
  return pixels;
}

cv::Mat RenderSyntheticView(const CameraModel& camera, const std::vector<SyntheticMarker>& markers,
                            const SyntheticViewOptions& options) {
  if (!options.Check()) throw std::invalid_argument("RenderSyntheticView: invalid options");
  if (camera.model != DistortionModel::kNone || camera.width <= 0 || camera.height <= 0 ||
      !(camera.fx > 0.0) || !(camera.fy > 0.0)) {
    throw std::invalid_argument("RenderSyntheticView: needs an undistorted pinhole camera");
  }
  cv::RNG rng(options.seed);
  const cv::Size size(camera.width, camera.height);
  cv::Mat image = options.background == SyntheticBackground::kTextured
                      ? TexturedBackground(size, options, rng)
                      : cv::Mat(size, CV_32F, cv::Scalar(options.background_mean));
  for (const SyntheticMarker& marker : markers) {
    DrawMarker(camera, marker, options.supersampling, image);
  }
  if (options.blur_sigma_px > 0.0) {
    cv::GaussianBlur(image, image, cv::Size(0, 0), options.blur_sigma_px);
  }
  if (options.noise_sigma > 0.0) {
    cv::Mat noise(size, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, options.noise_sigma);
    image += noise;
  }
  cv::Mat result;
  image.convertTo(result, CV_8U);  // rounds and saturates to 0..255
  return result;
}

cv::Mat ThroughJpeg(const cv::Mat& image, int quality) {
  std::vector<uchar> bytes;
  cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, quality});
  return cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
}

CameraModel SyntheticCamera640() {
  return PinholeCamera(640, 480, 500.0);
}

}  // namespace arucoslam
