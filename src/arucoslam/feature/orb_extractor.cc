#include "arucoslam/feature/orb_extractor.h"

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <queue>
#include <stdexcept>

#include "arucoslam/feature/quadtree_spread.h"

namespace arucoslam {
namespace {

constexpr int kFastBorder = 3;  // FAST tests a circle of radius 3

std::vector<int> FeaturesPerLevel(const OrbExtractorOptions& options) {
  const double area_ratio = 1.0 / (options.scale_factor * options.scale_factor);
  const int levels = options.num_levels;
  const double first =
      options.num_features * (1.0 - area_ratio) / (1.0 - std::pow(area_ratio, levels));
  std::vector<int> counts(levels, 0);
  int assigned = 0;
  for (int level = 0; level + 1 < levels; ++level) {
    counts[level] = static_cast<int>(std::lround(first * std::pow(area_ratio, level)));
    assigned += counts[level];
  }
  counts[levels - 1] = std::max(0, options.num_features - assigned);
  return counts;
}

std::vector<cv::Mat> BuildPyramid(const cv::Mat& image, const ScalePyramid& pyramid) {
  std::vector<cv::Mat> levels(pyramid.num_levels);
  levels[0] = image;
  for (int level = 1; level < pyramid.num_levels; ++level) {
    const cv::Size size(static_cast<int>(std::lround(image.cols * pyramid.inverse_scales[level])),
                        static_cast<int>(std::lround(image.rows * pyramid.inverse_scales[level])));
    if (size.width < 1 || size.height < 1) break;
    cv::resize(levels[level - 1], levels[level], size, 0.0, 0.0, cv::INTER_LINEAR);
  }
  return levels;
}

// FAST corners inside [margin, cols - margin) x [margin, rows - margin) of one level: the
// initial threshold over the whole region, the low one in grid cells left empty.
std::vector<cv::KeyPoint> DetectCorners(const cv::Mat& image, const OrbExtractorOptions& options) {
  const int margin = options.edge_margin_px;
  const cv::Rect inner(margin, margin, image.cols - 2 * margin, image.rows - 2 * margin);
  std::vector<cv::KeyPoint> corners;
  if (inner.width <= 0 || inner.height <= 0) return corners;
  const cv::Rect padded(inner.x - kFastBorder, inner.y - kFastBorder, inner.width + 2 * kFastBorder,
                        inner.height + 2 * kFastBorder);
  std::vector<cv::KeyPoint> found;
  cv::FAST(image(padded), found, options.initial_fast_threshold, true);
  const int cell = options.cell_size_px;
  const int cells_x = (inner.width + cell - 1) / cell;
  const int cells_y = (inner.height + cell - 1) / cell;
  std::vector<int> per_cell(cells_x * cells_y, 0);
  for (cv::KeyPoint& kp : found) {
    kp.pt.x += padded.x;
    kp.pt.y += padded.y;
    if (!inner.contains(cv::Point(cvRound(kp.pt.x), cvRound(kp.pt.y)))) continue;
    const int cx = (cvRound(kp.pt.x) - inner.x) / cell;
    const int cy = (cvRound(kp.pt.y) - inner.y) / cell;
    ++per_cell[cy * cells_x + cx];
    corners.push_back(kp);
  }
  if (options.min_fast_threshold >= options.initial_fast_threshold) return corners;
  for (int cy = 0; cy < cells_y; ++cy) {
    for (int cx = 0; cx < cells_x; ++cx) {
      if (per_cell[cy * cells_x + cx] > 0) continue;
      const cv::Rect cell_rect =
          cv::Rect(inner.x + cx * cell, inner.y + cy * cell, cell, cell) & inner;
      const cv::Rect search(cell_rect.x - kFastBorder, cell_rect.y - kFastBorder,
                            cell_rect.width + 2 * kFastBorder, cell_rect.height + 2 * kFastBorder);
      std::vector<cv::KeyPoint> weak;
      cv::FAST(image(search), weak, options.min_fast_threshold, true);
      for (cv::KeyPoint& kp : weak) {
        kp.pt.x += search.x;
        kp.pt.y += search.y;
        if (cell_rect.contains(cv::Point(cvRound(kp.pt.x), cvRound(kp.pt.y)))) {
          corners.push_back(kp);
        }
      }
    }
  }
  return corners;
}

// Half-width of the circular orientation patch for each row offset 0..radius.
std::vector<int> CircleHalfWidths(int radius) {
  std::vector<int> half_widths(radius + 1);
  for (int v = 0; v <= radius; ++v) {
    half_widths[v] = static_cast<int>(std::floor(std::sqrt(radius * radius - v * v + 1e-9)));
  }
  return half_widths;
}

// Orientation (degrees, [0, 360)) from the intensity centroid of the circular patch.
float IntensityCentroidAngle(const cv::Mat& image, int x, int y,
                             const std::vector<int>& half_widths) {
  const int radius = static_cast<int>(half_widths.size()) - 1;
  double m10 = 0.0, m01 = 0.0;
  for (int v = -radius; v <= radius; ++v) {
    const std::uint8_t* row = image.ptr<std::uint8_t>(y + v);
    const int width = half_widths[std::abs(v)];
    int row_sum = 0, row_moment = 0;
    for (int u = -width; u <= width; ++u) {
      const int value = row[x + u];
      row_sum += value;
      row_moment += u * value;
    }
    m10 += row_moment;
    m01 += static_cast<double>(v) * row_sum;
  }
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}

void Describe(const cv::Mat& blurred, const cv::KeyPoint& kp, const BriefPattern& pattern,
              std::uint8_t* descriptor) {
  const float angle = kp.angle * static_cast<float>(CV_PI / 180.0);
  const float c = std::cos(angle), s = std::sin(angle);
  const std::uint8_t* centre = blurred.ptr<std::uint8_t>(cvRound(kp.pt.y)) + cvRound(kp.pt.x);
  const int step = static_cast<int>(blurred.step1());
  auto sample = [&](float px, float py) {
    return centre[cvRound(px * s + py * c) * step + cvRound(px * c - py * s)];
  };
  for (int byte = 0; byte < kOrbDescriptorBytes; ++byte) {
    std::uint8_t value = 0;
    for (int bit = 0; bit < 8; ++bit) {
      const BriefPair& pair = pattern.pairs[8 * byte + bit];
      if (sample(pair.ax, pair.ay) < sample(pair.bx, pair.by)) value |= (1u << bit);
    }
    descriptor[byte] = value;
  }
}

}  // namespace

bool OrbExtractorOptions::Check() const {
  return num_features > 0 && num_levels >= 1 && num_levels <= 32 && scale_factor > 1.0 &&
         initial_fast_threshold > 0 && min_fast_threshold > 0 &&
         min_fast_threshold <= initial_fast_threshold && cell_size_px >= 8 &&
         edge_margin_px >= kOrientationPatchRadius + 1;
}

OrbExtractor::OrbExtractor(const OrbExtractorOptions& options)
    : options_(options),
      pyramid_(ScalePyramid::Make(options.num_levels, options.scale_factor)),
      features_per_level_(FeaturesPerLevel(options)),
      pattern_(BriefPattern::Generate()) {
  if (!options_.Check()) throw std::invalid_argument("OrbExtractorOptions: invalid values");
}

OrbFeatures OrbExtractor::Extract(const cv::Mat& image) const {
  if (image.empty() || image.type() != CV_8UC1) {
    throw std::invalid_argument("OrbExtractor::Extract: expected a non-empty CV_8UC1 image");
  }
  OrbFeatures features;
  features.pyramid = pyramid_;
  features.image_width = image.cols;
  features.image_height = image.rows;
  const std::vector<cv::Mat> levels = BuildPyramid(image, pyramid_);
  const std::vector<int> half_widths = CircleHalfWidths(kOrientationPatchRadius);
  std::vector<cv::Mat> level_descriptors;
  for (int level = 0; level < pyramid_.num_levels; ++level) {
    const cv::Mat& level_image = levels[level];
    if (level_image.empty()) break;
    std::vector<cv::KeyPoint> corners = DetectCorners(level_image, options_);
    corners = SpreadWithQuadtree(corners, cv::Rect(0, 0, level_image.cols, level_image.rows),
                                 features_per_level_[level]);
    if (corners.empty()) continue;
    cv::Mat blurred;
    cv::GaussianBlur(level_image, blurred, cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
    cv::Mat descriptors(static_cast<int>(corners.size()), kOrbDescriptorBytes, CV_8U);
    const double sx = static_cast<double>(image.cols) / level_image.cols;
    const double sy = static_cast<double>(image.rows) / level_image.rows;
    for (std::size_t i = 0; i < corners.size(); ++i) {
      cv::KeyPoint& kp = corners[i];
      kp.angle =
          IntensityCentroidAngle(level_image, cvRound(kp.pt.x), cvRound(kp.pt.y), half_widths);
      Describe(blurred, kp, pattern_, descriptors.ptr<std::uint8_t>(static_cast<int>(i)));
      // Pixel centres map as (x + 0.5) * scale - 0.5 between levels.
      kp.pt.x = static_cast<float>((kp.pt.x + 0.5) * sx - 0.5);
      kp.pt.y = static_cast<float>((kp.pt.y + 0.5) * sy - 0.5);
      kp.octave = level;
      kp.size = static_cast<float>(2 * kOrientationPatchRadius + 1) *
                static_cast<float>(pyramid_.scales[level]);
      kp.class_id = -1;
    }
    features.keypoints.insert(features.keypoints.end(), corners.begin(), corners.end());
    level_descriptors.push_back(descriptors);
  }
  if (!level_descriptors.empty()) {
    cv::vconcat(level_descriptors, features.descriptors);
  } else {
    features.descriptors.create(0, kOrbDescriptorBytes, CV_8U);
  }
  return features;
}

}  // namespace arucoslam
