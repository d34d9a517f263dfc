#include "dynorb/dynamic/fast_correspondence.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <opencv2/video/tracking.hpp>

#include "dynorb/features/orb_matcher.h"

namespace dynorb {

std::vector<cv::Mat> BuildLkPyramid(const cv::Mat& gray, const LkOptions& options) {
  std::vector<cv::Mat> pyramid;
  cv::buildOpticalFlowPyramid(gray, pyramid, cv::Size(options.window_px, options.window_px), options.levels, true);
  return pyramid;
}

namespace {

// The element at index size/2 once sorted (the upper median); `values` must not be empty.
float UpperMedian(std::vector<float> values) {
  const auto mid = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

// Per-axis median of result - guess over the points that converged (status set, residual at most
// max_residual); zero with fewer than min_points of them.
cv::Point2f MedianOffset(const std::vector<cv::Point2f>& result,
                         const std::vector<cv::Point2f>& guess, const std::vector<uint8_t>& status,
                         const std::vector<float>& error, float max_residual, int min_points) {
  std::vector<float> dx, dy;
  for (size_t i = 0; i < result.size(); ++i) {
    if (!status[i] || error[i] > max_residual) continue;
    dx.push_back(result[i].x - guess[i].x);
    dy.push_back(result[i].y - guess[i].y);
  }
  if (dx.empty() || static_cast<int>(dx.size()) < min_points) return {0.f, 0.f};
  return {UpperMedian(std::move(dx)), UpperMedian(std::move(dy))};
}

// LK on the base image only from the guesses in *previous (cheap: a good guess converges there);
// the points that end farther than base_first_px from their guess (plus, with
// base_shift_min_points, the converged points' median offset), fail, or end with a large residual
// are tracked again through the whole pyramid from their guess (plus that offset).
// Returns the number of points tracked again.
int TrackBaseFirst(const std::vector<cv::Mat>& previous_pyramid,
                   const std::vector<cv::Mat>& current_pyramid,
                   const std::vector<cv::Point2f>& current, const LkOptions& options,
                   std::vector<cv::Point2f>* previous, std::vector<uint8_t>* status) {
  const cv::Size window(options.window_px, options.window_px);
  const int base_side = options.base_window_px > 0 ? options.base_window_px : options.window_px;
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                  options.iterations, options.epsilon_px);
  const std::vector<cv::Point2f> guess = *previous;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(current_pyramid, previous_pyramid, current, *previous, *status, error,
                           cv::Size(base_side, base_side), 0, criteria,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  // A point stuck near its guess (no gradient towards the true position) ends there with a
  // residual far above what converged points have: the gate is 3x the median residual.
  std::vector<float> residuals;
  for (size_t i = 0; i < current.size(); ++i) {
    if ((*status)[i]) residuals.push_back(error[i]);
  }
  const float max_residual = residuals.empty() ? 0.f : 3.f * UpperMedian(std::move(residuals));
  const cv::Point2f shift = options.base_shift_min_points > 0
                                ? MedianOffset(*previous, guess, *status, error, max_residual,
                                               options.base_shift_min_points)
                                : cv::Point2f(0.f, 0.f);
  const double max2 = options.base_first_px * options.base_first_px;
  std::vector<int> again;
  for (size_t i = 0; i < current.size(); ++i) {
    const cv::Point2f d = (*previous)[i] - guess[i] - shift;
    if (!(*status)[i] || d.x * d.x + d.y * d.y > max2 || error[i] > max_residual) {
      again.push_back(static_cast<int>(i));
    }
  }
  if (again.empty() || options.levels == 0) return 0;
  std::vector<cv::Point2f> from, to;
  for (int i : again) {
    from.push_back(current[i]);
    to.push_back(guess[i] + shift);
  }
  std::vector<uint8_t> again_status;
  cv::calcOpticalFlowPyrLK(current_pyramid, previous_pyramid, from, to, again_status, error, window, options.levels,
                           criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
  for (size_t k = 0; k < again.size(); ++k) {
    (*previous)[again[k]] = to[k];
    (*status)[again[k]] = again_status[k];
  }
  return static_cast<int>(again.size());
}

}  // namespace

Correspondences TrackWithFlow(const std::vector<cv::Mat>& previous_pyramid, const std::vector<cv::Mat>& current_pyramid,
                              const std::vector<cv::Point2f>& current, const std::vector<cv::Point2f>& initial_previous,
                              const LkOptions& options) {
  Correspondences c;
  const size_t n = current.size();
  c.valid.assign(n, 0);
  c.for_f.assign(n, 0);
  c.previous = initial_previous.size() == n ? initial_previous : current;
  if (n == 0) return c;
  const cv::Size window(options.window_px, options.window_px);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                  options.iterations, options.epsilon_px);
  std::vector<uint8_t> status, back_status;
  std::vector<float> error;
  if (options.base_first_px > 0.0 && initial_previous.size() == n) {
    c.num_retracked =
        TrackBaseFirst(previous_pyramid, current_pyramid, current, options, &c.previous, &status);
  } else {
    cv::calcOpticalFlowPyrLK(current_pyramid, previous_pyramid, current, c.previous, status, error, window,
                             options.levels, criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
  }
  std::vector<cv::Point2f> back = current;
  if (options.backward_check) {
    cv::calcOpticalFlowPyrLK(previous_pyramid, current_pyramid, c.previous, back, back_status,
                             error, window, options.BackwardLevels(), criteria,
                             cv::OPTFLOW_USE_INITIAL_FLOW);
  } else {
    back_status.assign(n, 1);
  }
  const cv::Size size = current_pyramid.empty() ? cv::Size() : current_pyramid[0].size();
  const double max2 = options.fb_max_px * options.fb_max_px;
  for (size_t i = 0; i < n; ++i) {
    if (!status[i] || !back_status[i]) continue;
    const cv::Point2f d = back[i] - current[i];
    if (d.x * d.x + d.y * d.y > max2) continue;
    const cv::Point2f& p = c.previous[i];
    if (p.x < 0 || p.y < 0 || p.x > size.width - 1 || p.y > size.height - 1) continue;
    c.valid[i] = 1;
    c.for_f[i] = 1;
    ++c.num_valid;
  }
  return c;
}

Correspondences TrackSubsetWithFlow(const std::vector<cv::Mat>& previous_pyramid,
                                    const std::vector<cv::Mat>& current_pyramid, const std::vector<cv::Point2f>& current,
                                    const std::vector<int>& indices, const std::vector<cv::Point2f>& initial_previous,
                                    const LkOptions& options) {
  std::vector<cv::Point2f> points;
  points.reserve(indices.size());
  for (int i : indices) points.push_back(current[i]);
  const Correspondences sub = TrackWithFlow(previous_pyramid, current_pyramid, points, initial_previous, options);
  Correspondences c;
  c.previous = current;
  c.valid.assign(current.size(), 0);
  c.for_f.assign(current.size(), 0);
  for (size_t k = 0; k < indices.size(); ++k) {
    c.previous[indices[k]] = sub.previous[k];
    c.valid[indices[k]] = sub.valid[k];
    c.for_f[indices[k]] = sub.for_f[k];
  }
  c.num_valid = sub.num_valid;
  c.num_retracked = sub.num_retracked;
  return c;
}

int CheckBackward(const std::vector<cv::Mat>& previous_pyramid, const std::vector<cv::Mat>& current_pyramid,
                  const std::vector<cv::Point2f>& current, const std::vector<int>& indices, const LkOptions& options,
                  Correspondences* c) {
  if (indices.empty()) return 0;
  std::vector<cv::Point2f> from, back;
  for (int i : indices) {
    from.push_back(c->previous[i]);
    back.push_back(current[i]);
  }
  std::vector<uint8_t> status;
  std::vector<float> error;
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                  options.iterations, options.epsilon_px);
  cv::calcOpticalFlowPyrLK(previous_pyramid, current_pyramid, from, back, status, error,
                           cv::Size(options.window_px, options.window_px), options.BackwardLevels(),
                           criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
  const double max2 = options.fb_max_px * options.fb_max_px;
  int invalidated = 0;
  for (size_t k = 0; k < indices.size(); ++k) {
    const int i = indices[k];
    const cv::Point2f d = back[k] - current[i];
    if (status[k] && d.x * d.x + d.y * d.y <= max2) continue;
    if (c->valid[i]) --c->num_valid, ++invalidated;
    c->valid[i] = 0;
    c->for_f[i] = 0;
  }
  return invalidated;
}

std::vector<int> SpreadSubset(const std::vector<cv::KeyPoint>& keypoints, cv::Size image, int max_points) {
  const int n = static_cast<int>(keypoints.size());
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  if (max_points <= 0 || n <= max_points || image.width <= 0 || image.height <= 0) return all;
  constexpr int kCols = 16, kRows = 12;
  std::vector<std::vector<int>> cells(kCols * kRows);
  for (int i = 0; i < n; ++i) {
    const int cx = std::clamp(static_cast<int>(keypoints[i].pt.x * kCols / image.width), 0, kCols - 1);
    const int cy = std::clamp(static_cast<int>(keypoints[i].pt.y * kRows / image.height), 0, kRows - 1);
    cells[cy * kCols + cx].push_back(i);
  }
  for (auto& cell : cells) {
    std::stable_sort(cell.begin(), cell.end(),
                     [&keypoints](int a, int b) { return keypoints[a].response > keypoints[b].response; });
  }
  std::vector<int> chosen;
  for (size_t round = 0; static_cast<int>(chosen.size()) < max_points; ++round) {
    std::vector<int> this_round;
    for (const auto& cell : cells) {
      if (round < cell.size()) this_round.push_back(cell[round]);
    }
    if (this_round.empty()) break;
    std::sort(this_round.begin(), this_round.end());
    for (int i : this_round) {
      if (static_cast<int>(chosen.size()) == max_points) break;
      chosen.push_back(i);
    }
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

Correspondences MatchDescriptors(const cv::Mat& current_descriptors, const cv::Mat& previous_descriptors,
                                 const std::vector<cv::Point2f>& previous_points, int max_distance,
                                 double best_fraction, double max_ratio) {
  Correspondences c;
  const size_t n = static_cast<size_t>(current_descriptors.rows);
  c.valid.assign(n, 0);
  c.for_f.assign(n, 0);
  c.previous.assign(n, cv::Point2f(0.f, 0.f));
  c.previous_index.assign(n, -1);
  if (n == 0 || previous_descriptors.rows == 0) return c;
  BruteForceMatchOptions options;
  options.max_distance = max_distance;
  options.max_ratio = max_ratio;
  options.mutual_check = true;
  std::vector<DescriptorMatch> matches = MatchBruteForce(current_descriptors, previous_descriptors, options);
  for (const DescriptorMatch& m : matches) {
    c.valid[m.query_index] = 1;
    c.previous[m.query_index] = previous_points[m.train_index];
    c.previous_index[m.query_index] = m.train_index;
    ++c.num_valid;
  }
  // Best fraction by distance (ties by index: deterministic) for F.
  std::stable_sort(matches.begin(), matches.end(),
                   [](const DescriptorMatch& a, const DescriptorMatch& b) { return a.distance < b.distance; });
  const size_t keep = std::max<size_t>(std::min<size_t>(matches.size(), 8),
                                       static_cast<size_t>(std::ceil(best_fraction * matches.size())));
  for (size_t i = 0; i < keep; ++i) c.for_f[matches[i].query_index] = 1;
  return c;
}

}  // namespace dynorb
