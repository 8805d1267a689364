#include "arucoslam/markers/edge_refiner.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "arucoslam/geometry/image_sampling.h"
#include "arucoslam/markers/line_fit.h"

namespace arucoslam {
namespace {

// Fits the edge along side a->b whose outward normal is `outward`: at points spread along
// the side, the grey profile across it is read and the dark-to-bright step located as the
// centroid of the outward derivative around its strongest (positive) peak. nullopt with
// too few edge points.
std::optional<FittedLine> FitSide(const cv::Mat& gray, cv::Point2d a, cv::Point2d b,
                                  cv::Point2d outward, double search_px, double min_fraction,
                                  double min_step, double derivative_half_width_px) {
  const double length = cv::norm(b - a);
  const int samples = std::clamp(static_cast<int>(length / 1.5), 4, 24);
  const double step = 0.25;  // px along the normal
  const int half = std::max(2, static_cast<int>(std::ceil(search_px / step)));
  std::vector<cv::Point2d> points;
  std::vector<double> weights;
  std::vector<double> profile(2 * half + 3);
  for (int s = 0; s < samples; ++s) {
    // Stay off the corners, where the neighbouring side's edge would pull.
    const double t = 0.12 + 0.76 * (s + 0.5) / samples;
    const cv::Point2d p = a + t * (b - a);
    for (int k = -half - 1; k <= half + 1; ++k) {
      const cv::Point2d q = p + (k * step) * outward;
      profile[k + half + 1] = BilinearGrey(gray, q.x, q.y);
    }
    // Derivative over +-derivative_half_width_px (in steps of 0.25 px each way).
    const int reach = std::max(1, static_cast<int>(std::lround(derivative_half_width_px / step)));
    std::vector<double> derivative(profile.size(), 0.0);
    int peak = -1;
    for (int i = 1; i + 1 < static_cast<int>(profile.size()); ++i) {
      const int lo = std::max(0, i - reach), hi = std::min<int>(profile.size() - 1, i + reach);
      derivative[i] = (profile[hi] - profile[lo]) / ((hi - lo) * step);
      if (peak < 0 || std::abs(derivative[i]) > std::abs(derivative[peak])) peak = i;
    }
    // The strongest step must be dark to bright outwards and clear of the noise.
    if (peak < 0 || derivative[peak] * 2.0 < min_step) continue;
    // The marker's edge is the innermost strong step: further out, a bright surround
    // beyond the quiet zone may step up again.
    for (int i = 1; i < peak; ++i) {
      if (derivative[i] >= 0.5 * derivative[peak] && derivative[i] >= derivative[i - 1] &&
          derivative[i] >= derivative[i + 1]) {
        peak = i;
        break;
      }
    }
    double sum = 0.0, moment = 0.0;
    for (int i = std::max(1, peak - 6); i <= std::min<int>(profile.size() - 2, peak + 6); ++i) {
      if (derivative[i] <= 0.0) continue;
      sum += derivative[i];
      moment += derivative[i] * (i - half - 1) * step;
    }
    points.push_back(p + (moment / sum) * outward);
    weights.push_back(derivative[peak]);
  }
  if (points.size() < std::max<size_t>(3, static_cast<size_t>(min_fraction * samples))) {
    return std::nullopt;
  }
  std::vector<WeightedPoint> weighted(points.size());
  for (size_t i = 0; i < points.size(); ++i) weighted[i] = {points[i], weights[i]};
  return FitWeightedLine(weighted);
}

}  // namespace

bool RefineQuadEdges(const cv::Mat& gray, int cells, const EdgeRefineOptions& options,
                     std::array<cv::Point2f, 4>& corners) {
  const std::array<cv::Point2f, 4> start = corners;
  double perimeter = 0.0;
  for (int k = 0; k < 4; ++k) perimeter += cv::norm(corners[(k + 1) % 4] - corners[k]);
  const double cell = 0.25 * perimeter / cells;
  std::array<cv::Point2d, 4> current;
  for (int k = 0; k < 4; ++k) current[k] = corners[k];
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    std::array<FittedLine, 4> lines;
    for (int k = 0; k < 4; ++k) {
      const cv::Point2d a = current[k], b = current[(k + 1) % 4];
      const cv::Point2d along = (b - a) * (1.0 / std::max(1e-9, cv::norm(b - a)));
      // Clockwise on screen with y down: the outside is on the left of a->b.
      const cv::Point2d outward(along.y, -along.x);
      const std::optional<FittedLine> line =
          FitSide(gray, a, b, outward, options.search_cells * cell, options.min_edge_fraction,
                  options.min_step, options.derivative_half_width_px);
      if (!line) return false;
      lines[k] = *line;
    }
    for (int k = 0; k < 4; ++k) {
      const std::optional<cv::Point2d> corner = IntersectLines(lines[(k + 3) % 4], lines[k]);
      if (!corner) return false;
      current[k] = *corner;
    }
  }
  for (int k = 0; k < 4; ++k) {
    if (cv::norm(current[k] - cv::Point2d(start[k])) > options.max_shift_cells * cell) return false;
  }
  for (int k = 0; k < 4; ++k) corners[k] = cv::Point2f(current[k]);
  return true;
}

}  // namespace arucoslam
