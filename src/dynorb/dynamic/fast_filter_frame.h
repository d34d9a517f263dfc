// FastFilter::FrameWork: one frame's intermediate results, handed from stage to stage of
// FastFilter::Filter (fast_filter.cc, fast_filter_classify.cc). Internal to the dynamic module.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "dynorb/dynamic/fast_correspondence.h"
#include "dynorb/dynamic/fast_cues.h"
#include "dynorb/dynamic/fast_filter.h"
#include "dynorb/dynamic/motion_ego.h"

namespace dynorb {

struct FastFilter::FrameWork {
  FrameWork(const FilterInput& in, const FastOptions& options)
      : input(in),
        keypoints(in.keypoints->keypoints),
        depth(*in.depth_m),
        n(keypoints.size()),
        max_depth(static_cast<float>(options.max_depth_m)),
        p2(n),
        history(n, 0) {
    for (size_t i = 0; i < n; ++i) p2[i] = keypoints[i].pt;
  }
  const FilterInput& input;
  const std::vector<cv::KeyPoint>& keypoints;
  const cv::Mat& depth;  // current frame, metres
  const size_t n;
  const float max_depth;
  bool after_carry = false;     // the previous frame was carried, not analysed
  std::vector<cv::Point2f> p2;  // current keypoint positions
  std::vector<cv::Point2f> p1;  // their positions in the previous frame (when tracked)
  std::vector<cv::Mat> pyramid;  // current frame's LK pyramid (flow mode)
  cv::Mat descriptors;           // current frame's descriptors (descriptor mode)
  Correspondences corr;
  std::vector<Rigid3d> motion_seeds;  // prev_from_cur, in priority order
  EgoMotionResult ego;
  WarpResidualResult warp;
  Eigen::Matrix3d f21 = Eigen::Matrix3d::Zero();
  bool have_f = false;
  std::vector<uint8_t> static_ref;  // F inliers (or, F replaced, the ego-motion's static points)
  std::vector<uint8_t> seed, confident_static;
  std::vector<uint16_t> history;  // track memory, one bit per frame (newest lowest)
  cv::Mat final_mask;             // full-resolution dynamic region mask
};

}  // namespace dynorb
