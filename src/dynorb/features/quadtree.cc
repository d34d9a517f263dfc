#include "dynorb/features/quadtree.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dynorb {
namespace {

struct Node {
  float x0, y0, x1, y1;  // half-open box [x0, x1) × [y0, y1)
  std::vector<int> members;

  // Nodes smaller than a pixel in both directions hold one integer position at most.
  bool Splittable() const { return members.size() > 1 && (x1 - x0 >= 1.f || y1 - y0 >= 1.f); }
};

// Splits `node` into up to four non-empty children appended to `out` (order: UL, UR, BL, BR).
void Split(const Node& node, const std::vector<cv::KeyPoint>& keypoints, std::vector<Node>* out) {
  const float xm = 0.5f * (node.x0 + node.x1);
  const float ym = 0.5f * (node.y0 + node.y1);
  Node children[4] = {{node.x0, node.y0, xm, ym, {}},
                      {xm, node.y0, node.x1, ym, {}},
                      {node.x0, ym, xm, node.y1, {}},
                      {xm, ym, node.x1, node.y1, {}}};
  for (int i : node.members) {
    const cv::Point2f& p = keypoints[i].pt;
    children[(p.x < xm ? 0 : 1) + (p.y < ym ? 0 : 2)].members.push_back(i);
  }
  for (Node& c : children) {
    if (!c.members.empty()) out->push_back(std::move(c));
  }
}

// Number of non-empty children Split() would produce.
int CountChildren(const Node& node, const std::vector<cv::KeyPoint>& keypoints) {
  const float xm = 0.5f * (node.x0 + node.x1);
  const float ym = 0.5f * (node.y0 + node.y1);
  bool occupied[4] = {false, false, false, false};
  for (int i : node.members) {
    const cv::Point2f& p = keypoints[i].pt;
    occupied[(p.x < xm ? 0 : 1) + (p.y < ym ? 0 : 2)] = true;
  }
  return occupied[0] + occupied[1] + occupied[2] + occupied[3];
}

}  // namespace

std::vector<int> DistributeQuadtree(const std::vector<cv::KeyPoint>& keypoints,
                                    const cv::Rect2f& region, int target) {
  const int n = static_cast<int>(keypoints.size());
  if (target <= 0 || n == 0) return {};
  if (n <= target) {
    std::vector<int> all(n);
    std::iota(all.begin(), all.end(), 0);
    return all;
  }

  // Root nodes: a row or column of ≈square cells covering the region.
  const int n_cols = std::max(1, static_cast<int>(std::lround(region.width / region.height)));
  const int n_rows = std::max(1, static_cast<int>(std::lround(region.height / region.width)));
  const float cw = region.width / n_cols, ch = region.height / n_rows;
  std::vector<Node> nodes;
  {
    std::vector<Node> roots(n_cols * n_rows);
    for (int r = 0; r < n_rows; ++r) {
      for (int c = 0; c < n_cols; ++c) {
        roots[r * n_cols + c] = Node{region.x + c * cw,
                                     region.y + r * ch,
                                     region.x + (c + 1) * cw,
                                     region.y + (r + 1) * ch,
                                     {}};
      }
    }
    for (int i = 0; i < n; ++i) {
      const cv::Point2f& p = keypoints[i].pt;
      const int c = std::clamp(static_cast<int>((p.x - region.x) / cw), 0, n_cols - 1);
      const int r = std::clamp(static_cast<int>((p.y - region.y) / ch), 0, n_rows - 1);
      roots[r * n_cols + c].members.push_back(i);
    }
    for (Node& root : roots) {
      if (!root.members.empty()) nodes.push_back(std::move(root));
    }
  }

  std::vector<Node> next;
  std::vector<int> expandable;
  while (static_cast<int>(nodes.size()) < target) {
    expandable.clear();
    for (int i = 0; i < static_cast<int>(nodes.size()); ++i) {
      if (nodes[i].Splittable()) expandable.push_back(i);
    }
    if (expandable.empty()) break;

    std::vector<bool> split(nodes.size(), false);
    if (nodes.size() + 3 * expandable.size() <= static_cast<size_t>(target)) {
      for (int i : expandable) split[i] = true;  // a full round cannot overshoot the budget
    } else {
      // Split the most populated nodes first until the budget is reached.
      std::stable_sort(expandable.begin(), expandable.end(), [&](int a, int b) {
        return nodes[a].members.size() > nodes[b].members.size();
      });
      size_t count = nodes.size();
      for (int i : expandable) {
        split[i] = true;
        count += CountChildren(nodes[i], keypoints) - 1;
        if (count >= static_cast<size_t>(target)) break;
      }
    }
    next.clear();
    for (size_t i = 0; i < nodes.size(); ++i) {
      if (split[i]) {
        Split(nodes[i], keypoints, &next);
      } else {
        next.push_back(std::move(nodes[i]));
      }
    }
    nodes.swap(next);
  }

  std::vector<int> kept;
  kept.reserve(nodes.size());
  for (const Node& node : nodes) {
    int best = node.members.front();
    for (int i : node.members) {
      if (keypoints[i].response > keypoints[best].response) best = i;
    }
    kept.push_back(best);
  }
  return kept;
}

}  // namespace dynorb
