#include "arucoslam/feature/quadtree_spread.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <queue>

#include "arucoslam/feature/bucket_order.h"

namespace arucoslam {
namespace {

// A quadtree cell and its keypoints: members[begin, end) of the one array of keypoint
// indices that the cells share (the order inside a cell does not matter).
struct Cell {
  float x0, y0, x1, y1;  // [x0, x1) x [y0, y1)
  int begin, end;
  int Size() const { return end - begin; }
};

// Cells with more members are split first; ties broken by creation order (deterministic).
struct CellOrder {
  const std::vector<Cell>* cells;
  bool operator()(int a, int b) const {
    const int na = (*cells)[a].Size(), nb = (*cells)[b].Size();
    return na != nb ? na < nb : a > b;
  }
};

int Strongest(const std::vector<cv::KeyPoint>& keypoints, const std::vector<int>& members,
              const Cell& cell) {
  return *std::max_element(
      members.begin() + cell.begin, members.begin() + cell.end, [&](int a, int b) {
        return keypoints[a].response != keypoints[b].response
                   ? keypoints[a].response < keypoints[b].response
                   : a > b;
      });
}

// Reorders the cell's members by quadrant about (mx, my): (x >= mx) + 2 (y >= my). Returns
// where each quadrant's members start, and the cell's end.
std::array<int, 5> PartitionIntoQuadrants(const std::vector<cv::KeyPoint>& keypoints,
                                          std::vector<int>& members, const Cell& cell, float mx,
                                          float my) {
  const auto first = members.begin();
  const auto above = [&](int i) { return keypoints[i].pt.y < my; };
  const auto left = [&](int i) { return keypoints[i].pt.x < mx; };
  const auto lower_half = std::partition(first + cell.begin, first + cell.end, above);
  const auto upper_right = std::partition(first + cell.begin, lower_half, left);
  const auto lower_right = std::partition(lower_half, first + cell.end, left);
  return {cell.begin, static_cast<int>(upper_right - first), static_cast<int>(lower_half - first),
          static_cast<int>(lower_right - first), cell.end};
}

}  // namespace

std::vector<cv::KeyPoint> SpreadWithQuadtree(const std::vector<cv::KeyPoint>& keypoints,
                                             const cv::Rect& region, int target) {
  if (target <= 0 || keypoints.empty()) return {};
  if (static_cast<int>(keypoints.size()) <= target) return keypoints;
  std::vector<Cell> cells;
  cells.reserve(4 * static_cast<std::size_t>(target) + 8);
  // Roughly square root cells side by side along the longer axis.
  const int roots_x =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(region.width) / region.height)));
  const int roots_y =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(region.height) / region.width)));
  const float root_w = static_cast<float>(region.width) / roots_x;
  const float root_h = static_cast<float>(region.height) / roots_y;
  // The keypoints sorted by root cell.
  std::vector<int> root_of(keypoints.size());
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    const int rx =
        std::clamp(static_cast<int>((keypoints[i].pt.x - region.x) / root_w), 0, roots_x - 1);
    const int ry =
        std::clamp(static_cast<int>((keypoints[i].pt.y - region.y) / root_h), 0, roots_y - 1);
    root_of[i] = ry * roots_x + rx;
  }
  BucketOrder by_root = SortIntoBuckets(root_of, roots_x * roots_y);
  std::vector<int>& members = by_root.members;  // reordered as cells split
  const std::vector<int>& root_begin = by_root.begin;
  for (int ry = 0; ry < roots_y; ++ry) {
    for (int rx = 0; rx < roots_x; ++rx) {
      const int root = ry * roots_x + rx;
      cells.push_back({region.x + rx * root_w, region.y + ry * root_h,
                       region.x + (rx + 1) * root_w, region.y + (ry + 1) * root_h,
                       root_begin[root], root_begin[root + 1]});
    }
  }
  std::priority_queue<int, std::vector<int>, CellOrder> queue(CellOrder{&cells});
  std::vector<int> leaves;  // cells that are final (one member or too small to split)
  int occupied = 0;
  for (int c = 0; c < static_cast<int>(cells.size()); ++c) {
    if (cells[c].Size() == 0) continue;
    ++occupied;
    queue.push(c);
  }
  while (!queue.empty() && occupied < target) {
    const int c = queue.top();
    queue.pop();
    const Cell cell = cells[c];
    if (cell.Size() <= 1 || cell.x1 - cell.x0 < 1.0f || cell.y1 - cell.y0 < 1.0f) {
      leaves.push_back(c);
      if (cell.Size() <= 1) break;  // every remaining cell has one member
      continue;
    }
    const float mx = 0.5f * (cell.x0 + cell.x1), my = 0.5f * (cell.y0 + cell.y1);
    const std::array<int, 5> bounds = PartitionIntoQuadrants(keypoints, members, cell, mx, my);
    const Cell children[4] = {{cell.x0, cell.y0, mx, my, bounds[0], bounds[1]},
                              {mx, cell.y0, cell.x1, my, bounds[1], bounds[2]},
                              {cell.x0, my, mx, cell.y1, bounds[2], bounds[3]},
                              {mx, my, cell.x1, cell.y1, bounds[3], bounds[4]}};
    --occupied;
    for (const Cell& child : children) {
      if (child.Size() == 0) continue;
      ++occupied;
      cells.push_back(child);
      queue.push(static_cast<int>(cells.size()) - 1);
    }
  }
  while (!queue.empty()) {
    leaves.push_back(queue.top());
    queue.pop();
  }
  std::vector<cv::KeyPoint> chosen;
  chosen.reserve(leaves.size());
  for (int c : leaves) chosen.push_back(keypoints[Strongest(keypoints, members, cells[c])]);
  if (static_cast<int>(chosen.size()) > target) {
    std::stable_sort(
        chosen.begin(), chosen.end(),
        [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.response > b.response; });
    chosen.resize(target);
  }
  return chosen;
}

}  // namespace arucoslam
