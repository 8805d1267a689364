#include "arucoslam/feature/quadtree_spread.h"

#include <algorithm>
#include <cmath>
#include <queue>

namespace arucoslam {
namespace {

struct Cell {
  float x0, y0, x1, y1;      // [x0, x1) x [y0, y1)
  std::vector<int> members;  // indices into the keypoints
};

// Cells with more members are split first; ties broken by creation order (deterministic).
struct CellOrder {
  const std::vector<Cell>* cells;
  bool operator()(int a, int b) const {
    const std::size_t na = (*cells)[a].members.size(), nb = (*cells)[b].members.size();
    return na != nb ? na < nb : a > b;
  }
};

int Strongest(const std::vector<cv::KeyPoint>& keypoints, const std::vector<int>& members) {
  return *std::max_element(members.begin(), members.end(), [&](int a, int b) {
    return keypoints[a].response != keypoints[b].response
               ? keypoints[a].response < keypoints[b].response
               : a > b;
  });
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
  for (int ry = 0; ry < roots_y; ++ry) {
    for (int rx = 0; rx < roots_x; ++rx) {
      cells.push_back({region.x + rx * root_w,
                       region.y + ry * root_h,
                       region.x + (rx + 1) * root_w,
                       region.y + (ry + 1) * root_h,
                       {}});
    }
  }
  for (int i = 0; i < static_cast<int>(keypoints.size()); ++i) {
    const int rx =
        std::clamp(static_cast<int>((keypoints[i].pt.x - region.x) / root_w), 0, roots_x - 1);
    const int ry =
        std::clamp(static_cast<int>((keypoints[i].pt.y - region.y) / root_h), 0, roots_y - 1);
    cells[ry * roots_x + rx].members.push_back(i);
  }
  std::priority_queue<int, std::vector<int>, CellOrder> queue(CellOrder{&cells});
  std::vector<int> leaves;  // cells that are final (one member or too small to split)
  int occupied = 0;
  for (int c = 0; c < static_cast<int>(cells.size()); ++c) {
    if (cells[c].members.empty()) continue;
    ++occupied;
    queue.push(c);
  }
  while (!queue.empty() && occupied < target) {
    const int c = queue.top();
    queue.pop();
    if (cells[c].members.size() <= 1 || cells[c].x1 - cells[c].x0 < 1.0f ||
        cells[c].y1 - cells[c].y0 < 1.0f) {
      leaves.push_back(c);
      if (cells[c].members.size() <= 1) break;  // every remaining cell has one member
      continue;
    }
    // A split cell is never looked at again; its children take its members.
    const Cell cell = {cells[c].x0, cells[c].y0, cells[c].x1, cells[c].y1,
                       std::move(cells[c].members)};
    const float mx = 0.5f * (cell.x0 + cell.x1), my = 0.5f * (cell.y0 + cell.y1);
    Cell children[4] = {{cell.x0, cell.y0, mx, my, {}},
                        {mx, cell.y0, cell.x1, my, {}},
                        {cell.x0, my, mx, cell.y1, {}},
                        {mx, my, cell.x1, cell.y1, {}}};
    for (int member : cell.members) {
      const cv::Point2f& p = keypoints[member].pt;
      children[(p.x >= mx ? 1 : 0) + (p.y >= my ? 2 : 0)].members.push_back(member);
    }
    --occupied;
    for (Cell& child : children) {
      if (child.members.empty()) continue;
      ++occupied;
      cells.push_back(std::move(child));
      queue.push(static_cast<int>(cells.size()) - 1);
    }
  }
  while (!queue.empty()) {
    leaves.push_back(queue.top());
    queue.pop();
  }
  std::vector<cv::KeyPoint> chosen;
  chosen.reserve(leaves.size());
  for (int c : leaves) chosen.push_back(keypoints[Strongest(keypoints, cells[c].members)]);
  if (static_cast<int>(chosen.size()) > target) {
    std::stable_sort(
        chosen.begin(), chosen.end(),
        [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.response > b.response; });
    chosen.resize(target);
  }
  return chosen;
}

}  // namespace arucoslam
