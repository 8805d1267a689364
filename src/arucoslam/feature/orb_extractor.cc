#include "arucoslam/feature/orb_extractor.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "arucoslam/feature/bucket_order.h"
#include "arucoslam/feature/quadtree_spread.h"
#include "arucoslam/util/option_check.h"

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

// The pyramid's images, each built from the one above it when first asked for, so that the
// threads can start on the large levels before the small ones exist.
class LazyPyramid {
 public:
  LazyPyramid(const cv::Mat& image, const ScalePyramid& pyramid)
      : pyramid_(pyramid), levels_(pyramid.num_levels) {
    levels_[0] = image;
  }

  // Level `level`'s image; empty when the level would be smaller than one pixel.
  const cv::Mat& Level(int level) {
    if (level == 0) return levels_[0];
    std::lock_guard<std::mutex> lock(mutex_);
    const cv::Mat& image = levels_[0];
    for (; built_ < level; ++built_) {
      const int next = built_ + 1;
      const cv::Size size(
          static_cast<int>(std::lround(image.cols * pyramid_.inverse_scales[next])),
          static_cast<int>(std::lround(image.rows * pyramid_.inverse_scales[next])));
      if (size.width < 1 || size.height < 1 || levels_[built_].empty()) continue;
      cv::resize(levels_[built_], levels_[next], size, 0.0, 0.0, cv::INTER_LINEAR);
    }
    return levels_[level];
  }

 private:
  const ScalePyramid& pyramid_;
  std::vector<cv::Mat> levels_;
  std::mutex mutex_;
  int built_ = 0;  // levels [0, built_] exist (or are known to be empty)
};

// The 16 pixels of FAST's circle of radius 3 in order around it, as (x, y) offsets.
constexpr int kFastCircle[16][2] = {{0, 3},  {1, 3},   {2, 2},   {3, 1},   {3, 0},  {3, -1},
                                    {2, -2}, {1, -3},  {0, -3},  {-1, -3}, {-2, -2}, {-3, -1},
                                    {-3, 0}, {-3, 1},  {-2, 2},  {-1, 3}};
constexpr int kFastArc = 9;  // contiguous circle pixels that make a corner (TYPE_9_16)

#if CV_SIMD128
// Minima and maxima over arcs of the circle starting at each of its 16 pixels (lanes 0-7 in
// *_low, 8-15 in *_high): from arcs of kShift pixels to arcs of 2 kShift.
template <int kShift>
void WidenArcs(cv::v_int16x8& min_low, cv::v_int16x8& min_high, cv::v_int16x8& max_low,
               cv::v_int16x8& max_high) {
  const cv::v_int16x8 new_min_low = cv::v_min(min_low, cv::v_extract<kShift>(min_low, min_high));
  const cv::v_int16x8 new_min_high = cv::v_min(min_high, cv::v_extract<kShift>(min_high, min_low));
  const cv::v_int16x8 new_max_low = cv::v_max(max_low, cv::v_extract<kShift>(max_low, max_high));
  const cv::v_int16x8 new_max_high = cv::v_max(max_high, cv::v_extract<kShift>(max_high, max_low));
  min_low = new_min_low;
  min_high = new_min_high;
  max_low = new_max_low;
  max_high = new_max_high;
}
#endif

// cv::FAST's score of a pixel (TYPE_9_16), the one its non-maximum suppression compares: one
// less than the larger of `threshold` and the largest d for which kFastArc contiguous circle
// pixels are all darker, or all brighter, than the centre by at least d.
int FastCornerScore(const std::uint8_t* centre, int step, int threshold) {
  static_assert(kFastArc == 9, "arcs of 2, 4, 8, then one more pixel");
#if CV_SIMD128
  // Lane k of (low, high): centre minus circle pixel k.
  alignas(16) std::uint8_t circle[16];
  // Unrolled, so that the circle's offsets become constants once the row step is known.
#pragma GCC unroll 16
  for (int k = 0; k < 16; ++k) circle[k] = centre[kFastCircle[k][1] * step + kFastCircle[k][0]];
  cv::v_uint16x8 circle_low, circle_high;
  cv::v_expand(cv::v_load(circle), circle_low, circle_high);
  const cv::v_int16x8 value = cv::v_setall_s16(static_cast<std::int16_t>(centre[0]));
  const cv::v_int16x8 low = value - cv::v_reinterpret_as_s16(circle_low);
  const cv::v_int16x8 high = value - cv::v_reinterpret_as_s16(circle_high);
  cv::v_int16x8 min_low = low, min_high = high, max_low = low, max_high = high;
  WidenArcs<1>(min_low, min_high, max_low, max_high);
  WidenArcs<2>(min_low, min_high, max_low, max_high);
  WidenArcs<4>(min_low, min_high, max_low, max_high);
  // Arcs of 8 starting at k, then the pixel k + 8: the other half of the pair.
  const cv::v_int16x8 darker_low = cv::v_min(min_low, high), darker_high = cv::v_min(min_high, low);
  const cv::v_int16x8 brighter_low = cv::v_max(max_low, high);
  const cv::v_int16x8 brighter_high = cv::v_max(max_high, low);
  const cv::v_int16x8 zero = cv::v_setzero_s16();
  cv::v_int16x8 best = cv::v_max(cv::v_max(darker_low, darker_high),
                                 cv::v_max(zero - brighter_low, zero - brighter_high));
  return std::max(threshold, static_cast<int>(cv::v_reduce_max(best))) - 1;
#else
  int differences[16 + kFastArc - 1];
  for (int k = 0; k < 16 + kFastArc - 1; ++k) {
    differences[k] = centre[0] - centre[kFastCircle[k % 16][1] * step + kFastCircle[k % 16][0]];
  }
  int best = threshold;
  for (int start = 0; start < 16; ++start) {
    int smallest = differences[start], largest = differences[start];
    for (int k = start + 1; k < start + kFastArc; ++k) {
      smallest = std::min(smallest, differences[k]);
      largest = std::max(largest, differences[k]);
    }
    best = std::max(best, std::max(smallest, -largest));
  }
  return best - 1;
#endif
}

// The grid of cells over the detection region of one level that decides where the low
// threshold is tried; the last column and row of cells may be cut short by the region.
struct CellGrid {
  CellGrid(const cv::Rect& region, int cell_size)
      : region(region),
        cell_size(cell_size),
        cells_x((region.width + cell_size - 1) / cell_size),
        cells_y((region.height + cell_size - 1) / cell_size),
        corner_counts(static_cast<std::size_t>(cells_x) * cells_y, 0) {}

  int CellX(int x) const { return (x - region.x) / cell_size; }
  int CellY(int y) const { return (y - region.y) / cell_size; }
  // Corners of the initial threshold in the cell holding level pixel p.
  int& CountAt(const cv::Point& p) { return corner_counts[CellY(p.y) * cells_x + CellX(p.x)]; }
  bool Empty(int cx, int cy) const { return corner_counts[cy * cells_x + cx] == 0; }
  // Cells [cx_begin, cx_end) of row cy as one rectangle.
  cv::Rect Cells(int cx_begin, int cx_end, int cy) const {
    return cv::Rect(region.x + cx_begin * cell_size, region.y + cy * cell_size,
                    (cx_end - cx_begin) * cell_size, cell_size) &
           region;
  }

  cv::Rect region;
  int cell_size;
  int cells_x, cells_y;
  std::vector<int> corner_counts;  // corners of the initial threshold in each cell
};

cv::Rect PaddedForFast(const cv::Rect& rect) {
  return cv::Rect(rect.x - kFastBorder, rect.y - kFastBorder, rect.width + 2 * kFastBorder,
                  rect.height + 2 * kFastBorder);
}

// FAST scores over a rectangle with a frame of zeros, so that every pixel of the rectangle
// has eight neighbours; 0 where no candidate is.
class ScoreMap {
 public:
  explicit ScoreMap(const cv::Rect& rect)
      : rect_(rect),
        step_(rect.width + 2),
        scores_(static_cast<std::size_t>(step_) * (rect.height + 2), 0) {}
  std::uint8_t& At(const cv::Point& p) {
    return scores_[(p.y - rect_.y + 1) * step_ + (p.x - rect_.x + 1)];
  }

  // Whether the score at p is above those of its eight neighbours inside the columns
  // [x_begin, x_end) (the rows are the map's own); a neighbour outside counts as 0. This is
  // cv::FAST's non-maximum suppression when it searches those columns alone.
  bool StrongestAround(const cv::Point& p, int x_begin, int x_end) {
    const int score = At(p);
    const int left = p.x > x_begin ? -1 : 0, right = p.x + 1 < x_end ? 1 : 0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = left; dx <= right; ++dx) {
        if ((dx != 0 || dy != 0) && score <= At(cv::Point(p.x + dx, p.y + dy))) return false;
      }
    }
    return true;
  }

 private:
  cv::Rect rect_;
  int step_;
  std::vector<std::uint8_t> scores_;
};

// The FAST corners of `threshold` inside `region` before suppression, in level pixels and
// row-major, with their scores in `scores` (which covers `region`).
std::vector<cv::Point> ScoredCandidates(const cv::Mat& image, const cv::Rect& region,
                                        int threshold, ScoreMap& scores) {
  const cv::Rect search = PaddedForFast(region);
  // cv::FAST's output, kept from call to call (it only clears it) so that it grows only once.
  thread_local std::vector<cv::KeyPoint> found;
  cv::FAST(image(search), found, threshold, false);
  const int step = static_cast<int>(image.step1());
  std::vector<cv::Point> candidates;
  candidates.reserve(found.size());
  for (const cv::KeyPoint& kp : found) {
    const cv::Point pixel(cvRound(kp.pt.x) + search.x, cvRound(kp.pt.y) + search.y);
    scores.At(pixel) = static_cast<std::uint8_t>(
        FastCornerScore(image.ptr<std::uint8_t>(pixel.y) + pixel.x, step, threshold));
    candidates.push_back(pixel);
  }
  return candidates;
}

// A keypoint as cv::FAST reports one at level pixel `pixel`.
cv::KeyPoint FastKeypoint(const cv::Point& pixel, int score) {
  constexpr float kFastKeypointSize = 7.0f;
  return cv::KeyPoint(cv::Point2f(static_cast<float>(pixel.x), static_cast<float>(pixel.y)),
                      kFastKeypointSize, -1.0f, static_cast<float>(score));
}

// Corners of the initial threshold over the whole region, counted per cell, as one
// cv::FAST call with non-maximum suppression over it finds them.
void DetectStrongCorners(const cv::Mat& image, int threshold, CellGrid& grid,
                         std::vector<cv::KeyPoint>& corners) {
  ScoreMap scores(grid.region);
  const std::vector<cv::Point> candidates =
      ScoredCandidates(image, grid.region, threshold, scores);
  for (const cv::Point& pixel : candidates) {
    if (!scores.StrongestAround(pixel, grid.region.x, grid.region.br().x)) continue;
    ++grid.CountAt(pixel);
    corners.push_back(FastKeypoint(pixel, scores.At(pixel)));
  }
}

// Corners of `threshold` in the empty cells [cx_begin, cx_end) of row cy, appended cell by
// cell and row-major inside each, exactly as cv::FAST with non-maximum suppression finds them
// in each cell searched alone: a corner is kept when its score beats those of its eight
// neighbours inside its cell (a neighbour outside the cell counts as 0). One cv::FAST call
// over the whole run finds the candidates.
void DetectWeakCornersInRun(const cv::Mat& image, int threshold, const CellGrid& grid,
                            int cx_begin, int cx_end, int cy, std::vector<cv::KeyPoint>& corners) {
  const cv::Rect run = grid.Cells(cx_begin, cx_end, cy);
  ScoreMap scores(run);
  const std::vector<cv::Point> candidates = ScoredCandidates(image, run, threshold, scores);
  // The corners kept, sorted by cell (stable, so row-major inside each).
  std::vector<int> cell_of(candidates.size(), -1);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const int cx = grid.CellX(candidates[i].x);
    const cv::Rect cell = grid.Cells(cx, cx + 1, cy);
    if (scores.StrongestAround(candidates[i], cell.x, cell.br().x)) cell_of[i] = cx - cx_begin;
  }
  const BucketOrder by_cell = SortIntoBuckets(cell_of, cx_end - cx_begin);
  for (const int i : by_cell.members) {
    corners.push_back(FastKeypoint(candidates[i], scores.At(candidates[i])));
  }
}

// Corners of `threshold` in the cells the initial threshold left empty, row by row of cells;
// each run of adjacent empty cells of a row is searched at once.
void DetectWeakCorners(const cv::Mat& image, int threshold, const CellGrid& grid,
                       std::vector<cv::KeyPoint>& corners) {
  for (int cy = 0; cy < grid.cells_y; ++cy) {
    int cx = 0;
    while (cx < grid.cells_x) {
      if (!grid.Empty(cx, cy)) {
        ++cx;
        continue;
      }
      const int run_begin = cx;
      while (cx < grid.cells_x && grid.Empty(cx, cy)) ++cx;
      DetectWeakCornersInRun(image, threshold, grid, run_begin, cx, cy, corners);
    }
  }
}

// FAST corners inside [margin, cols - margin) x [margin, rows - margin) of one level: the
// initial threshold over the whole region, the low one in grid cells left empty.
std::vector<cv::KeyPoint> DetectCorners(const cv::Mat& image, const OrbExtractorOptions& options) {
  const int margin = options.edge_margin_px;
  const cv::Rect inner(margin, margin, image.cols - 2 * margin, image.rows - 2 * margin);
  std::vector<cv::KeyPoint> corners;
  if (inner.width <= 0 || inner.height <= 0) return corners;
  CellGrid grid(inner, options.cell_size_px);
  DetectStrongCorners(image, options.initial_fast_threshold, grid, corners);
  if (options.min_fast_threshold >= options.initial_fast_threshold) return corners;
  DetectWeakCorners(image, options.min_fast_threshold, grid, corners);
  return corners;
}

// The circular orientation patch of radius kOrientationPatchRadius: its half-width on each
// row offset, and the same as byte masks over the 32 columns u = -15..16 for the vector path.
struct CirclePatch {
  static constexpr int kRadius = kOrientationPatchRadius;
  static constexpr int kColumns = 32;
  static_assert(kColumns == 2 * kRadius + 2, "the vector path covers u = -15..16");

  CirclePatch() {
    for (int v = 0; v <= kRadius; ++v) {
      half_widths[v] = static_cast<int>(std::floor(std::sqrt(kRadius * kRadius - v * v + 1e-9)));
      for (int c = 0; c < kColumns; ++c) {
        masks[v][c] = std::abs(c - kRadius) <= half_widths[v] ? 0xFF : 0;
      }
    }
  }
  int half_widths[kRadius + 1];
  alignas(16) std::uint8_t masks[kRadius + 1][kColumns];
};

// Orientation (degrees, [0, 360)) from the intensity centroid of the circular patch around
// (x, y); rows +v and -v are taken together. The moments are exact integers.
float IntensityCentroidAngle(const cv::Mat& image, int x, int y, const CirclePatch& patch) {
  constexpr int kRadius = CirclePatch::kRadius;
  const std::uint8_t* centre = image.ptr<std::uint8_t>(y) + x;
  const int step = static_cast<int>(image.step1());
  int m10 = 0, m01 = 0;
#if CV_SIMD128
  // Columns u = -15..0 in the low halves, 1..16 in the high ones; u = 16 is always masked.
  alignas(16) static constexpr std::int16_t kU[4][8] = {{-15, -14, -13, -12, -11, -10, -9, -8},
                                                        {-7, -6, -5, -4, -3, -2, -1, 0},
                                                        {1, 2, 3, 4, 5, 6, 7, 8},
                                                        {9, 10, 11, 12, 13, 14, 15, 16}};
  cv::v_int16x8 u[4];
  for (int k = 0; k < 4; ++k) u[k] = cv::v_load(kU[k]);
  cv::v_int32x4 moment_x = cv::v_setzero_s32(), moment_y = cv::v_setzero_s32();
  for (int v = 0; v <= kRadius; ++v) {
    const std::uint8_t* up = centre - v * step - kRadius;
    const std::uint8_t* down = centre + v * step - kRadius;
    const cv::v_int16x8 weight_v = cv::v_setall_s16(static_cast<std::int16_t>(v));
    for (int half = 0; half < 2; ++half) {
      const cv::v_uint8x16 mask = cv::v_load(patch.masks[v] + 16 * half);
      const cv::v_uint8x16 a = cv::v_load(up + 16 * half) & mask;
      // Row 0 is counted once: as its own "down" row, with no "up" row.
      const cv::v_uint8x16 b = v == 0 ? cv::v_setzero_u8() : cv::v_load(down + 16 * half) & mask;
      cv::v_uint16x8 a_lo, a_hi, b_lo, b_hi;
      cv::v_expand(a, a_lo, a_hi);
      cv::v_expand(b, b_lo, b_hi);
      const cv::v_int16x8 sum_lo = cv::v_reinterpret_as_s16(a_lo + b_lo);
      const cv::v_int16x8 sum_hi = cv::v_reinterpret_as_s16(a_hi + b_hi);
      moment_x += cv::v_dotprod(sum_lo, u[2 * half]) + cv::v_dotprod(sum_hi, u[2 * half + 1]);
      if (v == 0) continue;
      const cv::v_int16x8 diff_lo = cv::v_reinterpret_as_s16(b_lo) - cv::v_reinterpret_as_s16(a_lo);
      const cv::v_int16x8 diff_hi = cv::v_reinterpret_as_s16(b_hi) - cv::v_reinterpret_as_s16(a_hi);
      moment_y += cv::v_dotprod(diff_lo + diff_hi, weight_v);
    }
  }
  m10 = cv::v_reduce_sum(moment_x);
  m01 = cv::v_reduce_sum(moment_y);
#else
  for (int u = -kRadius; u <= kRadius; ++u) m10 += u * centre[u];
  for (int v = 1; v <= kRadius; ++v) {
    const std::uint8_t* up = centre - v * step;
    const std::uint8_t* down = centre + v * step;
    const int width = patch.half_widths[v];
    int difference = 0;
    for (int u = -width; u <= width; ++u) {
      difference += down[u] - up[u];
      m10 += u * (down[u] + up[u]);
    }
    m01 += v * difference;
  }
#endif
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}

// The pattern's coordinates as four arrays, so that four points are rotated at a time.
struct PatternColumns {
  explicit PatternColumns(const BriefPattern& pattern) {
    for (std::size_t i = 0; i < pattern.pairs.size(); ++i) {
      ax[i] = pattern.pairs[i].ax;
      ay[i] = pattern.pairs[i].ay;
      bx[i] = pattern.pairs[i].bx;
      by[i] = pattern.pairs[i].by;
    }
  }
  static constexpr int kSize = 8 * kOrbDescriptorBytes;
  alignas(16) float ax[kSize], ay[kSize], bx[kSize], by[kSize];
};

// Offsets from the keypoint's pixel, in `step`-wide rows, of the pattern points (x, y)
// rotated by (cos, sin) = (c, s) and rounded as cvRound does (to nearest, ties to even).
void RotatedOffsets(const float* xs, const float* ys, float c, float s, int step, int* offsets) {
  int i = 0;
#if CV_SIMD128
  const cv::v_float32x4 vc = cv::v_setall_f32(c), vs = cv::v_setall_f32(s);
  const cv::v_int32x4 vstep = cv::v_setall_s32(step);
  for (; i + 4 <= PatternColumns::kSize; i += 4) {
    const cv::v_float32x4 x = cv::v_load(xs + i), y = cv::v_load(ys + i);
    const cv::v_int32x4 row = cv::v_round(x * vs + y * vc);
    const cv::v_int32x4 col = cv::v_round(x * vc - y * vs);
    cv::v_store(offsets + i, row * vstep + col);
  }
#endif
  for (; i < PatternColumns::kSize; ++i) {
    offsets[i] = cvRound(xs[i] * s + ys[i] * c) * step + cvRound(xs[i] * c - ys[i] * s);
  }
}

// Rotated BRIEF: bit 8 * byte + bit of the descriptor is set when the blurred intensity at
// the pair's first rotated point is below that at its second.
void Describe(const cv::Mat& blurred, const cv::KeyPoint& kp, const PatternColumns& pattern,
              std::uint8_t* descriptor) {
  const float angle = kp.angle * static_cast<float>(CV_PI / 180.0);
  const float c = std::cos(angle), s = std::sin(angle);
  const std::uint8_t* centre = blurred.ptr<std::uint8_t>(cvRound(kp.pt.y)) + cvRound(kp.pt.x);
  const int step = static_cast<int>(blurred.step1());
  alignas(16) int offsets_a[PatternColumns::kSize], offsets_b[PatternColumns::kSize];
  RotatedOffsets(pattern.ax, pattern.ay, c, s, step, offsets_a);
  RotatedOffsets(pattern.bx, pattern.by, c, s, step, offsets_b);
  int i = 0;
#if CV_SIMD128
  // Sixteen tests at a time: lane k of a comparison is bit k of the two bytes it fills.
  alignas(16) std::uint8_t first[16], second[16];
  for (; i + 16 <= PatternColumns::kSize; i += 16) {
    for (int k = 0; k < 16; ++k) {
      first[k] = centre[offsets_a[i + k]];
      second[k] = centre[offsets_b[i + k]];
    }
    const int bits = cv::v_signmask(cv::v_load(first) < cv::v_load(second));
    descriptor[i / 8] = static_cast<std::uint8_t>(bits & 0xFF);
    descriptor[i / 8 + 1] = static_cast<std::uint8_t>(bits >> 8);
  }
#endif
  for (; i < PatternColumns::kSize; i += 8) {
    unsigned value = 0;
    for (int bit = 0; bit < 8; ++bit) {
      value |= unsigned{centre[offsets_a[i + bit]] < centre[offsets_b[i + bit]]} << bit;
    }
    descriptor[i / 8] = static_cast<std::uint8_t>(value);
  }
}

}  // namespace

bool OrbExtractorOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Above("num_features", num_features, 0);
  check.InRange("num_levels", num_levels, 1, 32, Interval::kClosed);
  check.Above("scale_factor", scale_factor, 1.0);
  check.Above("initial_fast_threshold", initial_fast_threshold, 0);
  check.Above("min_fast_threshold", min_fast_threshold, 0);
  check.AtMost("min_fast_threshold", min_fast_threshold, initial_fast_threshold,
               "initial_fast_threshold");
  check.AtLeast("cell_size_px", cell_size_px, 8);
  check.AtLeast("edge_margin_px", edge_margin_px, kOrientationPatchRadius + 1,
                "kOrientationPatchRadius + 1");
  check.InRange("num_threads", num_threads, 1, 64, Interval::kClosed);
  return check.ok();
}

OrbExtractor::OrbExtractor(const OrbExtractorOptions& options)
    : options_(options),
      pyramid_(ScalePyramid::Make(options.num_levels, options.scale_factor)),
      features_per_level_(FeaturesPerLevel(options)),
      pattern_(BriefPattern::Generate()) {
  if (!options_.Check()) throw std::invalid_argument("OrbExtractorOptions: invalid values");
  if (options_.num_threads > 1) pool_ = std::make_unique<ThreadPool>(options_.num_threads);
}

OrbExtractor::~OrbExtractor() = default;
OrbExtractor::OrbExtractor(OrbExtractor&&) noexcept = default;
OrbExtractor& OrbExtractor::operator=(OrbExtractor&&) noexcept = default;

OrbExtractor::LevelFeatures OrbExtractor::ExtractLevel(const cv::Mat& level_image, int level,
                                                       cv::Size image_size) const {
  LevelFeatures result;
  std::vector<cv::KeyPoint> corners = DetectCorners(level_image, options_);
  corners = SpreadWithQuadtree(corners, cv::Rect(0, 0, level_image.cols, level_image.rows),
                               features_per_level_[level]);
  if (corners.empty()) return result;
  cv::Mat blurred;
  cv::GaussianBlur(level_image, blurred, cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
  result.descriptors.create(static_cast<int>(corners.size()), kOrbDescriptorBytes, CV_8U);
  const CirclePatch circle;
  const PatternColumns pattern(pattern_);
  const double sx = static_cast<double>(image_size.width) / level_image.cols;
  const double sy = static_cast<double>(image_size.height) / level_image.rows;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    cv::KeyPoint& kp = corners[i];
    kp.angle =
        IntensityCentroidAngle(level_image, cvRound(kp.pt.x), cvRound(kp.pt.y), circle);
    Describe(blurred, kp, pattern, result.descriptors.ptr<std::uint8_t>(static_cast<int>(i)));
    // Pixel centres map as (x + 0.5) * scale - 0.5 between levels.
    kp.pt.x = static_cast<float>((kp.pt.x + 0.5) * sx - 0.5);
    kp.pt.y = static_cast<float>((kp.pt.y + 0.5) * sy - 0.5);
    kp.octave = level;
    kp.size = static_cast<float>(2 * kOrientationPatchRadius + 1) *
              static_cast<float>(pyramid_.scales[level]);
    kp.class_id = -1;
  }
  result.keypoints = std::move(corners);
  return result;
}

OrbFeatures OrbExtractor::Extract(const cv::Mat& image) const {
  if (image.empty() || image.type() != CV_8UC1) {
    throw std::invalid_argument("OrbExtractor::Extract: expected a non-empty CV_8UC1 image");
  }
  OrbFeatures features;
  features.pyramid = pyramid_;
  features.image_width = image.cols;
  features.image_height = image.rows;
  LazyPyramid levels(image, pyramid_);
  std::vector<LevelFeatures> per_level(pyramid_.num_levels);
  const auto extract_level = [&](int level) {
    const cv::Mat& level_image = levels.Level(level);
    if (!level_image.empty()) per_level[level] = ExtractLevel(level_image, level, image.size());
  };
  // Levels are handed out largest first; each thread builds the pyramid down to its level.
  if (pool_) {
    pool_->ParallelFor(pyramid_.num_levels, extract_level);
  } else {
    for (int level = 0; level < pyramid_.num_levels; ++level) extract_level(level);
  }
  std::size_t total = 0;
  for (const LevelFeatures& level : per_level) total += level.keypoints.size();
  features.keypoints.reserve(total);
  features.descriptors.create(static_cast<int>(total), kOrbDescriptorBytes, CV_8U);
  int row = 0;
  for (const LevelFeatures& level : per_level) {
    if (level.keypoints.empty()) continue;
    features.keypoints.insert(features.keypoints.end(), level.keypoints.begin(),
                              level.keypoints.end());
    level.descriptors.copyTo(features.descriptors.rowRange(row, row + level.descriptors.rows));
    row += level.descriptors.rows;
  }
  return features;
}

}  // namespace arucoslam
