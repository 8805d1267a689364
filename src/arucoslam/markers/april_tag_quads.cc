#include "arucoslam/markers/april_tag_quads.h"

#include <algorithm>
#include <cmath>

namespace arucoslam {

std::vector<Quad> QuadsFromAprilTagDetection(
    const std::vector<std::vector<cv::Point2f>>& accepted,
    const std::vector<std::vector<cv::Point2f>>& rejected) {
  std::vector<Quad> quads;
  quads.reserve(accepted.size() + rejected.size());
  for (const auto* list : {&accepted, &rejected}) {
    for (const std::vector<cv::Point2f>& corners : *list) {
      if (corners.size() != 4) continue;
      Quad quad;
      for (int k = 0; k < 4; ++k) quad[k] = corners[k] - cv::Point2f(0.5f, 0.5f);
      quads.push_back(quad);
    }
  }
  return quads;
}

std::vector<Quad> FindAprilTagQuads(const cv::Mat& gray,
                                    const cv::Ptr<cv::aruco::Dictionary>& dictionary,
                                    const cv::aruco::DetectorParameters& parameters) {
  cv::Ptr<cv::aruco::DetectorParameters> april =
      cv::makePtr<cv::aruco::DetectorParameters>(parameters);
  april->cornerRefinementMethod = cv::aruco::CORNER_REFINE_APRILTAG;
  std::vector<std::vector<cv::Point2f>> accepted, rejected;
  std::vector<int> ids;
  cv::aruco::detectMarkers(gray, dictionary, accepted, ids, april, rejected);
  return QuadsFromAprilTagDetection(accepted, rejected);
}

std::vector<Quad> FindAprilTagQuadsAround(const cv::Mat& gray,
                                          const std::array<Eigen::Vector2d, 4>& corners,
                                          double margin_px,
                                          const cv::Ptr<cv::aruco::Dictionary>& dictionary,
                                          const cv::aruco::DetectorParameters& parameters) {
  constexpr int kTile = 4;  // the apriltag threshold's tile side
  Eigen::Vector2d low = corners[0], high = corners[0];
  for (const Eigen::Vector2d& corner : corners) {
    low = low.cwiseMin(corner);
    high = high.cwiseMax(corner);
  }
  const auto clamp = [](double value, int size) {
    return std::clamp(static_cast<int>(std::floor(value)), 0, size);
  };
  const int x0 = clamp(low.x() - margin_px, gray.cols) / kTile * kTile;
  const int y0 = clamp(low.y() - margin_px, gray.rows) / kTile * kTile;
  const int x1 = clamp(high.x() + margin_px + 1.0, gray.cols);
  const int y1 = clamp(high.y() + margin_px + 1.0, gray.rows);
  if (x1 - x0 < 2 * kTile || y1 - y0 < 2 * kTile) return {};
  std::vector<Quad> quads =
      FindAprilTagQuads(gray(cv::Rect(x0, y0, x1 - x0, y1 - y0)), dictionary, parameters);
  for (Quad& quad : quads) {
    for (cv::Point2f& corner : quad) corner += cv::Point2f(x0, y0);
  }
  return quads;
}

bool SnapCornersToQuad(const std::vector<Quad>& quads, int cells, double max_distance_cells,
                       std::array<Eigen::Vector2d, 4>& corners) {
  // Corner k may move max_distance_cells cells of its shorter side. A quad one cell inside
  // or outside the marker moves its most acute corner (90 degrees or less) by 1.4 cells.
  std::array<double, 4> max_distance;
  for (int k = 0; k < 4; ++k) {
    const double shorter = std::min((corners[(k + 1) % 4] - corners[k]).norm(),
                                    (corners[(k + 3) % 4] - corners[k]).norm());
    max_distance[k] = max_distance_cells * shorter / cells;
  }
  // The quad whose corners are nearest, relative to their tolerances.
  double best = 1.0;
  bool found = false;
  std::array<Eigen::Vector2d, 4> snapped;
  for (const Quad& quad : quads) {
    // Corner k of `corners` against corner (shift + direction * k) mod 4 of the quad.
    for (int shift = 0; shift < 4; ++shift) {
      for (const int direction : {1, 3}) {
        std::array<Eigen::Vector2d, 4> candidate;
        double farthest = 0.0;
        for (int k = 0; k < 4 && farthest < best; ++k) {
          const cv::Point2f& q = quad[(shift + direction * k) % 4];
          candidate[k] = Eigen::Vector2d(q.x, q.y);
          farthest = std::max(farthest, (candidate[k] - corners[k]).norm() / max_distance[k]);
        }
        if (farthest < best) {
          best = farthest;
          snapped = candidate;
          found = true;
        }
      }
    }
  }
  if (found) corners = snapped;
  return found;
}

}  // namespace arucoslam
