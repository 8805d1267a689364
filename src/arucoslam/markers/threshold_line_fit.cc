#include "arucoslam/markers/threshold_line_fit.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "arucoslam/markers/line_fit.h"
#include "arucoslam/util/option_check.h"

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

  // The threshold of each pixel of the window, -1 where the contrast is too low.
  cv::Mat1s PerPixel(cv::Rect window) const {
    std::vector<int> column_tile(window.width);
    for (int x = 0; x < window.width; ++x) column_tile[x] = TileX(window.x + x) - tx0_;
    cv::Mat1s map(window.size());
    for (int y = 0; y < window.height; ++y) {
      const int* tiles = &threshold_[(TileY(window.y + y) - ty0_) * width_];
      short* row = map[y];
      for (int x = 0; x < window.width; ++x) row[x] = static_cast<short>(tiles[column_tile[x]]);
    }
    return map;
  }

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

// The quad's sides as lines, each with the band of crossings it takes.
struct Sides {
  std::array<cv::Point2d, 4> start, along, outward;
  std::array<double, 4> length, band;

  // Whether `point` lies within `distance` of one of the sides' lines.
  bool Near(cv::Point2d point, double distance) const {
    for (int k = 0; k < 4; ++k) {
      if (std::abs((point - start[k]).dot(outward[k])) <= distance) return true;
    }
    return false;
  }

  // The side that takes a crossing at `point` stepping up towards `direction`: within its
  // band (+ slack px) of it, between its ends (+- slack px), dark inside; the nearest of
  // those. -1 when none.
  int Take(cv::Point2d point, cv::Point2d direction, double slack) const {
    int best = -1;
    double best_distance = 0.0;
    for (int k = 0; k < 4; ++k) {
      if (direction.dot(outward[k]) < 0.0) continue;  // bright inside
      const cv::Point2d offset = point - start[k];
      const double distance = std::abs(offset.dot(outward[k]));
      const double s = offset.dot(along[k]);
      if (distance > band[k] + slack || s < -slack || s > length[k] + slack) continue;
      if (best < 0 || distance < best_distance) {
        best = k;
        best_distance = distance;
      }
    }
    return best;
  }
};

// nullopt for a degenerate quad. `outward_sign`: +1 when the corners run clockwise on screen.
std::optional<Sides> MakeSides(const std::array<cv::Point2d, 4>& corners, double outward_sign,
                               int cells, const ThresholdLineFitOptions& options) {
  Sides sides;
  for (int k = 0; k < 4; ++k) {
    sides.start[k] = corners[k];
    const cv::Point2d side = corners[(k + 1) % 4] - corners[k];
    sides.length[k] = cv::norm(side);
    if (sides.length[k] < 1e-6) return std::nullopt;
    sides.along[k] = side * (1.0 / sides.length[k]);
    sides.outward[k] = outward_sign * cv::Point2d(sides.along[k].y, -sides.along[k].x);
  }
  for (int k = 0; k < 4; ++k) {
    // The marker's width at this side: how far inside the opposite side lies.
    const int opposite = (k + 2) % 4;
    const double width = -0.5 * ((corners[opposite] - corners[k]).dot(sides.outward[k]) +
                                 (corners[(opposite + 1) % 4] - corners[k]).dot(sides.outward[k]));
    sides.band[k] =
        std::clamp(options.band_cells * width / cells, options.min_band_px, options.max_band_px);
  }
  return sides;
}

// The crossings in `window` that `sides` takes with `slack`.
std::vector<Crossing> FindCrossings(const cv::Mat& gray, cv::Rect window,
                                    const ThresholdLineFitOptions& options, const Sides& sides,
                                    double slack) {
  const cv::Mat1s threshold =
      TileThreshold(gray, window, options.tile_px, options.min_contrast).PerPixel(window);
  // 0: dark, 1: bright, 2: neither.
  cv::Mat1b level(window.size());
  for (int y = 0; y < window.height; ++y) {
    const uchar* grey = gray.ptr<uchar>(window.y + y) + window.x;
    for (int x = 0; x < window.width; ++x) {
      const int t = threshold(y, x);
      level(y, x) = t < 0 ? 2 : grey[x] > t ? 1 : 0;
    }
  }
  // Each pixel with its right, lower and two lower diagonal neighbours.
  const cv::Point steps[] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}};
  std::vector<Crossing> crossings;
  // Pixels further than this from every side's line give no crossing that a side takes.
  const double reach = *std::max_element(sides.band.begin(), sides.band.end()) + slack + 1.5;
  for (int y = 0; y < window.height; ++y) {
    for (int x = 0; x < window.width; ++x) {
      const int level0 = level(y, x);
      if (level0 == 2 || !sides.Near(cv::Point2d(window.x + x, window.y + y), reach)) continue;
      for (const cv::Point& step : steps) {
        const int x1 = x + step.x, y1 = y + step.y;
        if (x1 < 0 || x1 >= window.width || y1 >= window.height) continue;
        const int level1 = level(y1, x1);
        if (level1 == 2 || level1 == level0) continue;
        // From the dark pixel to the bright one.
        cv::Point dark(x, y), bright(x1, y1);
        if (level0 == 1) std::swap(dark, bright);
        const int v_dark = gray.at<uchar>(window.y + dark.y, window.x + dark.x);
        const int v_bright = gray.at<uchar>(window.y + bright.y, window.x + bright.x);
        // The crossing of the (mean) threshold, interpolated linearly between the pixels.
        const double t = 0.5 * (threshold(dark) + threshold(bright)) + 0.5;
        const double f =
            v_bright != v_dark ? std::clamp((t - v_dark) / (v_bright - v_dark), 0.0, 1.0) : 0.5;
        const cv::Point2d origin(window.x, window.y);
        const cv::Point2d point = origin + cv::Point2d(dark) + f * cv::Point2d(bright - dark);
        const cv::Point2d direction = cv::Point2d(bright - dark) * (1.0 / cv::norm(bright - dark));
        if (sides.Take(point, direction, slack) < 0) continue;
        crossings.push_back({point, direction, GradientMagnitude(gray, point) + 1.0});
      }
    }
  }
  return crossings;
}

}  // namespace

bool ThresholdLineFitOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("tile_px", tile_px, 2);
  check.AtLeast("min_contrast", min_contrast, 0.0);
  check.Above("band_cells", band_cells, 0.0);
  check.AtLeast("min_band_px", min_band_px, 0.0);
  check.AtLeast("max_band_px", max_band_px, min_band_px, "min_band_px");
  check.AtLeast("iterations", iterations, 1);
  check.AtLeast("min_points_per_side", min_points_per_side, 2);
  check.Above("max_shift_cells", max_shift_cells, 0.0);
  return check.ok();
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

  // The crossings near the sides, with some slack for the sides' moves.
  const std::optional<Sides> initial = MakeSides(current, outward_sign, cells, options);
  if (!initial) return false;
  const double slack = 1.5;  // px
  const double margin = *std::max_element(initial->band.begin(), initial->band.end()) + slack + 1.0;
  const cv::Rect2d box = cv::boundingRect(std::vector<cv::Point2f>(corners.begin(), corners.end()));
  const cv::Rect window = cv::Rect(static_cast<int>(std::floor(box.x - margin)),
                                   static_cast<int>(std::floor(box.y - margin)),
                                   static_cast<int>(std::ceil(box.width + 2 * margin)) + 1,
                                   static_cast<int>(std::ceil(box.height + 2 * margin)) + 1) &
                          cv::Rect(0, 0, gray.cols, gray.rows);
  if (window.width < 2 || window.height < 2) return false;
  const std::vector<Crossing> crossings = FindCrossings(gray, window, options, *initial, slack);

  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    const std::optional<Sides> sides = MakeSides(current, outward_sign, cells, options);
    if (!sides) return false;
    std::array<std::vector<WeightedPoint>, 4> assigned;
    for (const Crossing& crossing : crossings) {
      const int k = sides->Take(crossing.point, crossing.direction, 0.0);
      if (k >= 0) assigned[k].push_back({crossing.point, crossing.weight});
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
