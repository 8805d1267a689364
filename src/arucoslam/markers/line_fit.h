// Straight lines for the corner refiners: a weighted total-least-squares fit of a line to
// points, and the intersection of two lines.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace arucoslam {

// The line normal.p = offset, with a unit normal.
struct FittedLine {
  cv::Point2d normal;
  double offset = 0.0;
};

struct WeightedPoint {
  cv::Point2d point;
  double weight = 1.0;  // > 0
};

// Minimises the weighted sum of squared distances to the line; needs two distinct points.
FittedLine FitWeightedLine(const std::vector<WeightedPoint>& points);

// nullopt for (nearly) parallel lines.
std::optional<cv::Point2d> IntersectLines(const FittedLine& a, const FittedLine& b);

}  // namespace arucoslam
