#include "arucoslam/markers/threshold_line_fit.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "arucoslam/markers/line_fit.h"

namespace arucoslam {
namespace {

// Per-pixel threshold over a window of the image: the mean of the lowest and highest grey
// level of the 3 x 3 tiles around the pixel's tile. Pixels past the last whole tile of a row
// or column use that tile.
class TileThreshold {
 public:
  TileThreshold(const cv::Mat& gray, cv::Rect window, int tile, double min_contrast)
      : tile_(tile), tiles_x_(gray.cols / tile), tiles_y_(gray.rows / tile) {
    tx0_ = TileX(window.x);
    ty0_ = TileY(window.y);
    const int tx1 = TileX(window.x + window.width - 1), ty1 = TileY(window.y + window.height - 1);
    width_ = tx1 - tx0_ + 1;
    height_ = ty1 - ty0_ + 1;
    // Lowest and highest level of each tile, one tile more on every side.
    const int ext_x0 = std::max(0, tx0_ - 1), ext_y0 = std::max(0, ty0_ - 1);
    const int ext_x1 = std::min(tiles_x_ - 1, tx1 + 1), ext_y1 = std::min(tiles_y_ - 1, ty1 + 1);
    const int ext_w = ext_x1 - ext_x0 + 1;
    std::vector<uchar> low(ext_w * (ext_y1 - ext_y0 + 1)), high(low.size());
    for (int ty = ext_y0; ty <= ext_y1; ++ty) {
      for (int tx = ext_x0; tx <= ext_x1; ++tx) {
        uchar lo = 255, hi = 0;
        for (int y = ty * tile; y < (ty + 1) * tile; ++y) {
          const uchar* row = gray.ptr<uchar>(y);
          for (int x = tx * tile; x < (tx + 1) * tile; ++x) {
            lo = std::min(lo, row[x]);
            hi = std::max(hi, row[x]);
          }
        }
        low[(ty - ext_y0) * ext_w + tx - ext_x0] = lo;
        high[(ty - ext_y0) * ext_w + tx - ext_x0] = hi;
      }
    }
    threshold_.assign(width_ * height_, -1);
    for (int ty = ty0_; ty < ty0_ + height_; ++ty) {
      for (int tx = tx0_; tx < tx0_ + width_; ++tx) {
        int lo = 255, hi = 0;
        for (int ny = std::max(ext_y0, ty - 1); ny <= std::min(ext_y1, ty + 1); ++ny) {
          for (int nx = std::max(ext_x0, tx - 1); nx <= std::min(ext_x1, tx + 1); ++nx) {
            lo = std::min<int>(lo, low[(ny - ext_y0) * ext_w + nx - ext_x0]);
            hi = std::max<int>(hi, high[(ny - ext_y0) * ext_w + nx - ext_x0]);
          }
        }
        // Integer mid-level: a pixel above it is bright, at or below it dark.
        if (hi - lo >= min_contrast)
          threshold_[(ty - ty0_) * width_ + tx - tx0_] = lo + (hi - lo) / 2;
      }
    }
  }

  // The pixel's threshold, -1 where the contrast is too low.
  int At(int x, int y) const { return threshold_[(TileY(y) - ty0_) * width_ + TileX(x) - tx0_]; }

 private:
  int TileX(int x) const { return std::min(x / tile_, tiles_x_ - 1); }
  int TileY(int y) const { return std::min(y / tile_, tiles_y_ - 1); }

  int tile_, tiles_x_, tiles_y_;
  int tx0_ = 0, ty0_ = 0, width_ = 0, height_ = 0;
  std::vector<int> threshold_;
};

// A dark-to-bright threshold crossing: where, which way (unit, towards bright), how strong.
struct Crossing {
  cv::Point2d point;
  cv::Point2d direction;
  double weight;
};

double GradientMagnitude(const cv::Mat& gray, cv::Point2d p) {
  const int x = std::clamp(static_cast<int>(std::lround(p.x)), 1, gray.cols - 2);
  const int y = std::clamp(static_cast<int>(std::lround(p.y)), 1, gray.rows - 2);
  const double gx = gray.at<uchar>(y, x + 1) - gray.at<uchar>(y, x - 1);
  const double gy = gray.at<uchar>(y + 1, x) - gray.at<uchar>(y - 1, x);
  return std::sqrt(gx * gx + gy * gy);
}

std::vector<Crossing> FindCrossings(const cv::Mat& gray, cv::Rect window,
                                    const ThresholdLineFitOptions& options) {
  const TileThreshold threshold(gray, window, options.tile_px, options.min_contrast);
  // Each pixel with its right, lower and two lower diagonal neighbours.
  const cv::Point steps[] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}};
  std::vector<Crossing> crossings;
  for (int y = window.y; y < window.y + window.height; ++y) {
    for (int x = window.x; x < window.x + window.width; ++x) {
      const int t0 = threshold.At(x, y);
      if (t0 < 0) continue;
      const int v0 = gray.at<uchar>(y, x);
      for (const cv::Point& step : steps) {
        const int x1 = x + step.x, y1 = y + step.y;
        if (x1 < window.x || x1 >= window.x + window.width || y1 >= window.y + window.height) {
          continue;
        }
        const int t1 = threshold.At(x1, y1);
        if (t1 < 0) continue;
        const int v1 = gray.at<uchar>(y1, x1);
        const bool bright0 = v0 > t0, bright1 = v1 > t1;
        if (bright0 == bright1) continue;
        // From the dark pixel to the bright one.
        cv::Point2d dark(x, y), bright(x1, y1);
        int v_dark = v0, v_bright = v1;
        if (bright0) {
          std::swap(dark, bright);
          std::swap(v_dark, v_bright);
        }
        // The crossing of the (mean) threshold, interpolated linearly between the pixels.
        double f = 0.5;
        if (v_bright != v_dark) {
          f = std::clamp((0.5 * (t0 + t1) + 0.5 - v_dark) / (v_bright - v_dark), 0.0, 1.0);
        }
        const cv::Point2d point = dark + f * (bright - dark);
        const cv::Point2d direction = (bright - dark) * (1.0 / cv::norm(bright - dark));
        crossings.push_back({point, direction, GradientMagnitude(gray, point) + 1.0});
      }
    }
  }
  return crossings;
}

}  // namespace

bool ThresholdLineFitOptions::Check() const {
  return tile_px >= 2 && min_contrast >= 0.0 && band_cells > 0.0 && min_band_px >= 0.0 &&
         iterations >= 1 && min_points_per_side >= 2 && max_shift_cells > 0.0;
}

bool FitQuadToThreshold(const cv::Mat& gray, int cells, const ThresholdLineFitOptions& options,
                        std::array<cv::Point2f, 4>& corners) {
  if (gray.type() != CV_8UC1 || gray.cols < 3 * options.tile_px ||
      gray.rows < 3 * options.tile_px) {
    return false;
  }
  std::array<cv::Point2d, 4> current;
  for (int k = 0; k < 4; ++k) current[k] = corners[k];
  double perimeter = 0.0;
  for (int k = 0; k < 4; ++k) perimeter += cv::norm(current[(k + 1) % 4] - current[k]);
  const double cell = 0.25 * perimeter / cells;
  // Signed area: positive when clockwise on screen (y down); the outside is then on the
  // left of each side a->b.
  double area = 0.0;
  for (int k = 0; k < 4; ++k) area += current[k].cross(current[(k + 1) % 4]);
  const double outward_sign = area > 0 ? 1.0 : -1.0;

  // Crossings over the quad's bounding box with room for the bands and corner moves.
  cv::Rect2d box = cv::boundingRect(std::vector<cv::Point2f>(corners.begin(), corners.end()));
  const double margin = std::max(options.min_band_px, options.band_cells * cell) +
                        options.max_shift_cells * cell + 2.0;
  const cv::Rect window = cv::Rect(static_cast<int>(std::floor(box.x - margin)),
                                   static_cast<int>(std::floor(box.y - margin)),
                                   static_cast<int>(std::ceil(box.width + 2 * margin)) + 1,
                                   static_cast<int>(std::ceil(box.height + 2 * margin)) + 1) &
                          cv::Rect(0, 0, gray.cols, gray.rows);
  if (window.width < 2 || window.height < 2) return false;
  const std::vector<Crossing> crossings = FindCrossings(gray, window, options);

  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    std::array<cv::Point2d, 4> start, along, outward;
    std::array<double, 4> length, band;
    for (int k = 0; k < 4; ++k) {
      start[k] = current[k];
      const cv::Point2d side = current[(k + 1) % 4] - current[k];
      length[k] = cv::norm(side);
      if (length[k] < 1e-6) return false;
      along[k] = side * (1.0 / length[k]);
      outward[k] = outward_sign * cv::Point2d(along[k].y, -along[k].x);
    }
    for (int k = 0; k < 4; ++k) {
      // The marker's width at this side: how far inside the opposite side lies.
      const int opposite = (k + 2) % 4;
      const double width = -0.5 * ((current[opposite] - start[k]).dot(outward[k]) +
                                   (current[(opposite + 1) % 4] - start[k]).dot(outward[k]));
      band[k] = std::max(options.min_band_px, options.band_cells * width / cells);
    }
    std::array<std::vector<WeightedPoint>, 4> assigned;
    for (const Crossing& crossing : crossings) {
      int best = -1;
      double best_distance = 0.0;
      for (int k = 0; k < 4; ++k) {
        const cv::Point2d offset = crossing.point - start[k];
        const double distance = std::abs(offset.dot(outward[k]));
        const double t = offset.dot(along[k]) / length[k];
        if (distance > band[k] || t < 0.0 || t > 1.0) continue;
        // Dark inside, bright outside: the crossing must not step up inwards.
        if (crossing.direction.dot(outward[k]) < 0.0) continue;  // not dark inside
        if (best < 0 || distance < best_distance) {
          best = k;
          best_distance = distance;
        }
      }
      if (best >= 0) assigned[best].push_back({crossing.point, crossing.weight});
    }
    std::array<FittedLine, 4> lines;
    for (int k = 0; k < 4; ++k) {
      if (static_cast<int>(assigned[k].size()) < options.min_points_per_side) return false;
      lines[k] = FitWeightedLine(assigned[k]);
    }
    for (int k = 0; k < 4; ++k) {
      const std::optional<cv::Point2d> corner = IntersectLines(lines[(k + 3) % 4], lines[k]);
      if (!corner) return false;
      current[k] = *corner;
    }
  }
  for (int k = 0; k < 4; ++k) {
    if (cv::norm(current[k] - cv::Point2d(corners[k])) > options.max_shift_cells * cell) {
      return false;
    }
  }
  for (int k = 0; k < 4; ++k) corners[k] = cv::Point2f(current[k]);
  return true;
}

}  // namespace arucoslam
