#include "arucoslam/markers/line_fit.h"

#include <cmath>

namespace arucoslam {

FittedLine FitWeightedLine(const std::vector<WeightedPoint>& points) {
  double weight_sum = 0.0;
  cv::Point2d mean(0, 0);
  for (const WeightedPoint& p : points) {
    weight_sum += p.weight;
    mean += p.weight * p.point;
  }
  mean *= 1.0 / weight_sum;
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (const WeightedPoint& p : points) {
    const cv::Point2d d = p.point - mean;
    sxx += p.weight * d.x * d.x;
    sxy += p.weight * d.x * d.y;
    syy += p.weight * d.y * d.y;
  }
  const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);  // direction of the line
  const cv::Point2d normal(-std::sin(angle), std::cos(angle));
  return FittedLine{normal, normal.dot(mean)};
}

std::optional<cv::Point2d> IntersectLines(const FittedLine& a, const FittedLine& b) {
  const double det = a.normal.x * b.normal.y - a.normal.y * b.normal.x;
  if (std::abs(det) < 1e-6) return std::nullopt;
  return cv::Point2d((a.offset * b.normal.y - b.offset * a.normal.y) / det,
                     (a.normal.x * b.offset - b.normal.x * a.offset) / det);
}

}  // namespace arucoslam
