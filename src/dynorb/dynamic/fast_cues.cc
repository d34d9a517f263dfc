#include "dynorb/dynamic/fast_cues.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dynorb/core/angles.h"
#include "dynorb/geometry/two_view.h"

namespace dynorb {

std::vector<CueVote> EpipolarCue(const Eigen::Matrix3d& f21, const std::vector<cv::Point2f>& p1,
                                 const std::vector<cv::Point2f>& p2, const std::vector<uint8_t>& valid,
                                 double t1_px, double t2_px) {
  std::vector<CueVote> votes(p1.size(), CueVote::kUnknown);
  for (size_t i = 0; i < p1.size(); ++i) {
    if (!valid[i]) continue;
    const double d = EpipolarDistancePx(f21, Eigen::Vector2d(p1[i].x, p1[i].y), Eigen::Vector2d(p2[i].x, p2[i].y));
    if (!std::isfinite(d)) continue;  // No epipolar line (the point is at the epipole): no evidence.
    votes[i] = d <= t1_px ? CueVote::kStatic : (d < t2_px ? CueVote::kMoving : CueVote::kMismatch);
  }
  return votes;
}

std::vector<CueVote> DirectionCue(const std::vector<cv::Point2f>& p1, const std::vector<cv::Point2f>& p2,
                                  const std::vector<uint8_t>& valid, const std::vector<uint8_t>& static_ref,
                                  double max_angle_deg, double min_flow_px) {
  const size_t n = p1.size();
  std::vector<CueVote> votes(n, CueVote::kUnknown);
  // Reference points bucketed in a coarse grid (cells of 32 px) for the nearest-neighbour search.
  constexpr float kCell = 32.f;
  std::vector<int> refs;
  float max_x = 0.f, max_y = 0.f;
  for (size_t i = 0; i < n; ++i) {
    if (!valid[i] || !static_ref[i]) continue;
    refs.push_back(static_cast<int>(i));
    max_x = std::max(max_x, p2[i].x);
    max_y = std::max(max_y, p2[i].y);
  }
  if (refs.empty()) return votes;
  const int cols = static_cast<int>(max_x / kCell) + 1, rows = static_cast<int>(max_y / kCell) + 1;
  auto cell_of = [&](const cv::Point2f& p, int* cx, int* cy) {
    *cx = std::clamp(static_cast<int>(p.x / kCell), 0, cols - 1);
    *cy = std::clamp(static_cast<int>(p.y / kCell), 0, rows - 1);
  };
  std::vector<std::vector<int>> grid(static_cast<size_t>(cols * rows));
  for (int r : refs) {
    int cx, cy;
    cell_of(p2[r], &cx, &cy);
    grid[cy * cols + cx].push_back(r);
  }
  const double cos_max = std::cos(DegToRad(max_angle_deg));
  for (size_t i = 0; i < n; ++i) {
    if (!valid[i]) continue;
    const cv::Point2f f = p2[i] - p1[i];
    const double len = std::hypot(f.x, f.y);
    int cx, cy;
    cell_of(p2[i], &cx, &cy);
    int best = -1;
    float best_d2 = std::numeric_limits<float>::max();
    // Expand rings until a reference is found and the ring is beyond the best distance.
    for (int ring = 0; ring < std::max(cols, rows); ++ring) {
      if (best >= 0 && (ring - 1) * kCell > std::sqrt(best_d2)) break;
      for (int y = cy - ring; y <= cy + ring; ++y) {
        for (int x = cx - ring; x <= cx + ring; ++x) {
          if (x < 0 || y < 0 || x >= cols || y >= rows) continue;
          if (std::max(std::abs(x - cx), std::abs(y - cy)) != ring) continue;
          for (int r : grid[y * cols + x]) {
            if (static_cast<size_t>(r) == i) continue;
            const cv::Point2f d = p2[r] - p2[i];
            const float d2 = d.x * d.x + d.y * d.y;
            if (d2 < best_d2) best_d2 = d2, best = r;
          }
        }
      }
    }
    if (best < 0) continue;
    const cv::Point2f g = p2[best] - p1[best];
    const double glen = std::hypot(g.x, g.y);
    // A flow of length 0 has no direction (min_flow_px 0 would otherwise compare 0 / 0).
    if (len < min_flow_px || glen < min_flow_px || len == 0.0 || glen == 0.0) continue;
    const double cosine = (f.x * g.x + f.y * g.y) / (len * glen);
    votes[i] = cosine < cos_max ? CueVote::kMoving : CueVote::kStatic;
  }
  return votes;
}

std::vector<CueVote> MagnitudeCue(const std::vector<cv::Point2f>& p1, const std::vector<cv::Point2f>& p2,
                                  const std::vector<uint8_t>& valid, double sigmas, double min_sigma_px,
                                  double abs_diff_px, MagnitudeStats* stats) {
  const size_t n = p1.size();
  std::vector<CueVote> votes(n, CueVote::kUnknown);
  std::vector<double> mag(n, 0.0);
  double sum = 0.0, sum2 = 0.0;
  int count = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!valid[i]) continue;
    mag[i] = std::hypot(p2[i].x - p1[i].x, p2[i].y - p1[i].y);
    sum += mag[i];
    sum2 += mag[i] * mag[i];
    ++count;
  }
  if (count < 2) return votes;
  const double mean = sum / count;
  const double sigma = std::sqrt(std::max(0.0, sum2 / count - mean * mean));
  if (stats != nullptr) *stats = {mean, sigma, count};
  const double limit = sigma < min_sigma_px ? abs_diff_px : sigmas * sigma;
  for (size_t i = 0; i < n; ++i) {
    if (!valid[i]) continue;
    votes[i] = std::abs(mag[i] - mean) > limit ? CueVote::kMoving : CueVote::kStatic;
  }
  return votes;
}

DepthSample SampleDepth(const cv::Mat& depth_m, const cv::Point2f& p, float max_depth_m) {
  DepthSample s;
  const int x0 = static_cast<int>(std::lround(p.x)), y0 = static_cast<int>(std::lround(p.y));
  if (x0 < 0 || y0 < 0 || x0 >= depth_m.cols || y0 >= depth_m.rows) return s;
  float lo = std::numeric_limits<float>::max(), hi = 0.f;
  for (int y = std::max(0, y0 - 1); y <= std::min(depth_m.rows - 1, y0 + 1); ++y) {
    const float* row = depth_m.ptr<float>(y);
    for (int x = std::max(0, x0 - 1); x <= std::min(depth_m.cols - 1, x0 + 1); ++x) {
      const float z = row[x];
      if (!(z > 0.f && z <= max_depth_m)) continue;
      lo = std::min(lo, z);
      hi = std::max(hi, z);
    }
  }
  if (hi == 0.f) return s;
  const float c = depth_m.at<float>(y0, x0);
  s.center = (c > 0.f && c <= max_depth_m) ? c : lo;
  s.min = lo;
  s.max = hi;
  return s;
}

WarpResidualResult WarpResidualCue(const PinholeCamera& camera, const Rigid3d& prev_from_cur,
                                   const std::vector<cv::Point2f>& p1, const std::vector<cv::Point2f>& p2,
                                   const std::vector<uint8_t>& valid, const cv::Mat& depth_cur,
                                   const cv::Mat& depth_prev, const WarpResidualOptions& options) {
  const size_t n = p1.size();
  WarpResidualResult out;
  out.residual_px.assign(n, -1.f);
  out.residual.assign(n, CueVote::kUnknown);
  out.depth.assign(n, CueVote::kUnknown);
  for (size_t i = 0; i < n; ++i) {
    if (!valid[i]) continue;
    const DepthSample z = SampleDepth(depth_cur, p2[i], options.max_depth_m);
    if (z.center <= 0.f) continue;
    // At a depth edge the keypoint may belong to either side: take the better explanation.
    double best = std::numeric_limits<double>::max(), best_z_prev = 0.0;
    cv::Point2f best_u;
    for (float zc : {z.center, z.min, z.max}) {
      double z_prev = 0.0;
      const cv::Point2f u = WarpToPrevious(camera, prev_from_cur, p2[i], zc, &z_prev);
      const double r = std::hypot(u.x - p1[i].x, u.y - p1[i].y);
      if (r < best) best = r, best_z_prev = z_prev, best_u = u;
    }
    out.residual_px[i] = static_cast<float>(best);
    const double flow = std::hypot(p2[i].x - p1[i].x, p2[i].y - p1[i].y);
    if (best > options.mismatch_px) {
      out.residual[i] = CueVote::kMismatch;  // and no depth vote either: the correspondence is wrong
      continue;
    }
    const double scale = options.tolerance_scale != nullptr ? (*options.tolerance_scale)[i] : 1.0;
    out.residual[i] =
        best > scale * options.residual_px + options.residual_rel * flow ? CueVote::kMoving : CueVote::kStatic;
    if (depth_prev.empty()) continue;
    const DepthSample zp = SampleDepth(depth_prev, p1[i], options.max_depth_m);
    if (zp.center <= 0.f) continue;
    const double tol = options.depth_abs_m + options.depth_rel * best_z_prev * best_z_prev;
    // Distance of the predicted depth to the previous 3×3 depth range.
    const double gap = std::max({0.0, zp.min - best_z_prev, best_z_prev - zp.max});
    out.depth[i] = gap > tol ? CueVote::kMoving : CueVote::kStatic;
  }
  return out;
}

}  // namespace dynorb
