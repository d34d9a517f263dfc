#include "dynorb/features/quadtree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>
#include <set>

namespace dynorb {
namespace {

cv::KeyPoint Kp(float x, float y, float response) {
  return cv::KeyPoint(x, y, 31.f, -1.f, response);
}

TEST(Quadtree, FewerKeypointsThanBudgetKeepsAll) {
  const std::vector<cv::KeyPoint> kps = {Kp(1, 1, 5), Kp(50, 2, 3), Kp(7, 90, 1)};
  EXPECT_EQ(DistributeQuadtree(kps, cv::Rect2f(0, 0, 100, 100), 5), (std::vector<int>{0, 1, 2}));
  EXPECT_TRUE(DistributeQuadtree(kps, cv::Rect2f(0, 0, 100, 100), 0).empty());
  EXPECT_TRUE(DistributeQuadtree({}, cv::Rect2f(0, 0, 100, 100), 10).empty());
}

TEST(Quadtree, OneStrongestPerQuadrantCluster) {
  // Four tight clusters, one per quadrant of a 200×200 region; budget 4 → the strongest of each.
  std::vector<cv::KeyPoint> kps;
  const cv::Point2f centres[4] = {{30, 30}, {170, 40}, {40, 160}, {150, 150}};
  for (int c = 0; c < 4; ++c) {
    for (int k = 0; k < 6; ++k) {
      kps.push_back(Kp(centres[c].x + k, centres[c].y + (k % 3), 10.f + ((k * 7 + c) % 6)));
    }
  }
  const std::vector<int> kept = DistributeQuadtree(kps, cv::Rect2f(0, 0, 200, 200), 4);
  ASSERT_EQ(kept.size(), 4u);
  std::set<int> clusters;
  for (int i : kept) {
    const int c = i / 6;
    clusters.insert(c);
    for (int k = 0; k < 6; ++k) EXPECT_GE(kps[i].response, kps[c * 6 + k].response);
  }
  EXPECT_EQ(clusters.size(), 4u);
}

TEST(Quadtree, ReachesBudgetAndSpreadsUniformly) {
  // Dense uniform lattice plus a very dense blob in one corner: the blob must not eat the budget.
  std::vector<cv::KeyPoint> kps;
  for (int y = 0; y < 480; y += 4) {
    for (int x = 0; x < 640; x += 4)
      kps.push_back(Kp(x, y, static_cast<float>((x * 31 + y * 17) % 50)));
  }
  for (int y = 0; y < 40; ++y) {
    for (int x = 1; x < 40; x += 2) kps.push_back(Kp(x, y + 0.5f, 100.f));
  }
  const int target = 300;
  const std::vector<int> kept = DistributeQuadtree(kps, cv::Rect2f(0, 0, 640, 480), target);
  EXPECT_GE(static_cast<int>(kept.size()), target);
  EXPECT_LE(static_cast<int>(kept.size()), target + 3);
  int in_blob = 0;
  std::set<int> cells;
  for (int i : kept) {
    if (kps[i].pt.x < 40 && kps[i].pt.y < 40) ++in_blob;
    cells.insert(static_cast<int>(kps[i].pt.y / 80) * 8 + static_cast<int>(kps[i].pt.x / 80));
  }
  EXPECT_LT(in_blob, 15);        // blob area is 0.5 % of the region
  EXPECT_EQ(cells.size(), 48u);  // every 80×80 cell of an 8×6 grid holds a keypoint
  std::vector<int> sorted = kept;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_TRUE(std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end());
}

}  // namespace
}  // namespace dynorb
