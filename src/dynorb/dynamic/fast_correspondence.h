// Correspondences between the previous and the current frame for the FAST dynamic mode, one
// entry per CURRENT keypoint (its position in the previous frame):
//  a. TrackWithFlow: pyramidal Lucas–Kanade (OpenCV) from the current keypoints into the previous
//     frame, optionally seeded with a predicted position, kept when the backward track returns
//     within fb_max_px of the start (forward–backward check; or later, for a subset only:
//     CheckBackward).
//  b. MatchDescriptors: brute-force Hamming matching of the current ORB descriptors against the
//     previous ones (mutual best, optional ratio test); all matches are correspondences, and the best
//     `best_fraction` by distance are marked for estimating F.
// Pure functions; thread-safe.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace dynorb {

struct Correspondences {
  std::vector<cv::Point2f> previous;  // position in the previous frame, per current keypoint
  std::vector<uint8_t> valid;         // 1 = tracked / matched
  std::vector<uint8_t> for_f;         // 1 = used to estimate the fundamental matrix
  std::vector<int> previous_index;    // descriptors: the matched previous keypoint (-1: none; empty for flow)
  int num_valid = 0;
  int num_retracked = 0;  // flow, base image first: points tracked again through the pyramid
};

struct LkOptions {
  int window_px = 21;
  int levels = 3;
  int iterations = 20;
  // LK stops a point's iterations when its update is below this (px).
  double epsilon_px = 0.01;
  double fb_max_px = 1.0;
  bool backward_check = true;  // false: forward tracks only (CheckBackward later, on a subset)
  // > 0 and a guess given: LK first on the base image only, from the guess; a point whose result
  // lies within base_first_px of its guess, with a residual at most 3x the median, keeps it; the
  // others (and failures) are tracked again through the whole pyramid from the guess. 0: the
  // whole pyramid for every point.
  double base_first_px = 0.0;
  int base_window_px = 0;  // window of that base-image pass (0: window_px)
  // With base_first_px: the median offset of the base pass's converged results from their
  // guesses (a shared error of the prediction, e.g. the camera's rotation jitter) is removed
  // before the base_first_px test, and the retracks start from guess + offset. Needs at least
  // base_shift_min_points converged points (0: off).
  int base_shift_min_points = 0;
  // Levels above the base image of the backward check (< 0 or > levels: all `levels`). It starts
  // from the point's current position, the right answer whenever the forward track was right.
  int backward_levels = -1;
  int BackwardLevels() const {
    return backward_levels >= 0 && backward_levels < levels ? backward_levels : levels;
  }
};

// The LK image pyramid (with derivatives) of one frame; built once per frame and reused as the
// "previous" pyramid of the next frame.
std::vector<cv::Mat> BuildLkPyramid(const cv::Mat& gray, const LkOptions& options);

// initial_previous: a guess of each point's previous position (empty: the current position).
Correspondences TrackWithFlow(const std::vector<cv::Mat>& previous_pyramid, const std::vector<cv::Mat>& current_pyramid,
                              const std::vector<cv::Point2f>& current, const std::vector<cv::Point2f>& initial_previous,
                              const LkOptions& options);

// TrackWithFlow for the points listed in `indices` only (e.g. SpreadSubset); initial_previous:
// one guess per listed point (empty: their current positions). The other points are invalid with
// previous = current.
Correspondences TrackSubsetWithFlow(const std::vector<cv::Mat>& previous_pyramid,
                                    const std::vector<cv::Mat>& current_pyramid, const std::vector<cv::Point2f>& current,
                                    const std::vector<int>& indices, const std::vector<cv::Point2f>& initial_previous,
                                    const LkOptions& options);

// The forward–backward check for the points listed in `indices` only: each is tracked back from
// c->previous into the current frame and invalidated (valid = for_f = 0) when it does not return
// within fb_max_px of `current`. Returns the number invalidated.
int CheckBackward(const std::vector<cv::Mat>& previous_pyramid, const std::vector<cv::Mat>& current_pyramid,
                  const std::vector<cv::Point2f>& current, const std::vector<int>& indices, const LkOptions& options,
                  Correspondences* c);

// At most max_points keypoint indices spread over the image: the strongest keypoint of every cell
// of a 16x12 grid first, then the second strongest of every cell, ... (ascending index order
// within a round; deterministic). All indices when max_points <= 0 or there are fewer keypoints.
std::vector<int> SpreadSubset(const std::vector<cv::KeyPoint>& keypoints, cv::Size image, int max_points);

// max_ratio: Lowe's ratio test (best < max_ratio × second best; 1 disables it).
Correspondences MatchDescriptors(const cv::Mat& current_descriptors, const cv::Mat& previous_descriptors,
                                 const std::vector<cv::Point2f>& previous_points, int max_distance,
                                 double best_fraction, double max_ratio = 1.0);

}  // namespace dynorb
