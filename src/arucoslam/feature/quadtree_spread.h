// SpreadWithQuadtree: picks at most N keypoints spread evenly over a region by splitting it
// like a quadtree until there are N occupied cells, then keeping the strongest of each cell.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace arucoslam {

// Returns at most `target` of `keypoints` (all of them if there are not more), at most one per
// final quadtree cell, the one with the highest `response`. Deterministic.
std::vector<cv::KeyPoint> SpreadWithQuadtree(const std::vector<cv::KeyPoint>& keypoints,
                                             const cv::Rect& region, int target);

}  // namespace arucoslam
