// Quadtree ("octree" in ORB-SLAM's code) distribution of keypoints over an image region.
//
// Mur-Artal et al., "ORB-SLAM: a Versatile and Accurate Monocular SLAM System", T-RO 2015, §III-A
// and the ORB-SLAM2 extractor: start from ≈square root nodes covering the region, split every node
// holding more than one keypoint into four quadrants (empty children are dropped) until the number
// of nodes reaches the budget or no node can be split; when the next full round would overshoot,
// split the most populated nodes first and stop as soon as the budget is reached. Each final node
// keeps its strongest keypoint (highest response; the earliest one on ties).
//
// Deterministic (no hashing, stable sorts). Pure function; thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace dynorb {

// Returns indices into `keypoints` of the kept keypoints (at most max(target, nodes) — the result
// may exceed `target` by up to 3 when the last split creates several nodes). All keypoints are
// returned, in input order, when there are no more than `target`. `region` must contain every
// keypoint position (x in [region.x, region.x + width), same for y).
std::vector<int> DistributeQuadtree(const std::vector<cv::KeyPoint>& keypoints,
                                    const cv::Rect2f& region, int target);

}  // namespace dynorb
