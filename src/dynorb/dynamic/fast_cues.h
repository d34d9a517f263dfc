// The point-wise moving-object cues of the FAST dynamic mode, as pure functions on
// correspondences p1 (previous frame) ↔ p2 (current frame), pixels. One vote per point:
//   EpipolarCue   d = |p2ᵀ F p1| / √(A² + B²) with (A, B, C) = F p1:  d ≤ t1 static, t1 < d < t2
//                 moving, d ≥ t2 mismatch (no evidence).
//   DirectionCue  the flow p2 − p1 compared with the flow of the nearest static point: angle
//                 difference above a threshold → moving (both flows long enough to have a direction).
//   MagnitudeCue  mean μ and standard deviation σ of |p2 − p1| over the valid points: |m − μ| > kσ
//                 → moving; when σ is below a floor, |m − μ| > an absolute difference decides.
//   WarpResidual  the rigid warp of a current point with depth into the previous frame,
//                 π(prev_from_cur · π⁻¹(p2, z)), compared with the tracked p1 (px), and the
//                 predicted depth compared with the previous depth map.
// Pure functions; thread-safe.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"

namespace dynorb {

enum class CueVote : uint8_t { kUnknown = 0, kStatic = 1, kMoving = 2, kMismatch = 3 };

// One vote per point from the distance of p2 to the epipolar line F·p1 (geometry's
// EpipolarDistancePx): <= t1 static, < t2 moving, else mismatch. Invalid points (valid[i] == 0)
// and points without an epipolar line (F·p1 has no direction) are kUnknown.
std::vector<CueVote> EpipolarCue(const Eigen::Matrix3d& f21, const std::vector<cv::Point2f>& p1,
                                 const std::vector<cv::Point2f>& p2, const std::vector<uint8_t>& valid,
                                 double t1_px, double t2_px);

// static_ref[i] != 0 marks the reference (static inlier) points. A point with no static point or
// a too short flow is kUnknown; a static point itself is compared with its nearest other one.
std::vector<CueVote> DirectionCue(const std::vector<cv::Point2f>& p1, const std::vector<cv::Point2f>& p2,
                                  const std::vector<uint8_t>& valid, const std::vector<uint8_t>& static_ref,
                                  double max_angle_deg, double min_flow_px);

struct MagnitudeStats {
  double mean_px = 0.0, sigma_px = 0.0;
  int count = 0;
};
std::vector<CueVote> MagnitudeCue(const std::vector<cv::Point2f>& p1, const std::vector<cv::Point2f>& p2,
                                  const std::vector<uint8_t>& valid, double sigmas, double min_sigma_px,
                                  double abs_diff_px, MagnitudeStats* stats = nullptr);

// Depth at a pixel with a 3×3 neighbourhood: nearest-pixel value and the min/max of the valid
// (0 < z ≤ max_depth_m) values; all 0 when none is valid.
struct DepthSample {
  float center = 0.f, min = 0.f, max = 0.f;
};
DepthSample SampleDepth(const cv::Mat& depth_m, const cv::Point2f& p, float max_depth_m);

// Where a current pixel with depth z lands in the previous frame.
inline cv::Point2f WarpToPrevious(const PinholeCamera& camera, const Rigid3d& prev_from_cur,
                                  const cv::Point2f& p2, double z, double* z_prev = nullptr) {
  const Eigen::Vector3d x = prev_from_cur * camera.Unproject(Eigen::Vector2d(p2.x, p2.y), z);
  if (z_prev != nullptr) *z_prev = x.z();
  if (x.z() <= 1e-6) return {-1e6f, -1e6f};
  const Eigen::Vector2d u = camera.Project(x);
  return {static_cast<float>(u.x()), static_cast<float>(u.y())};
}

struct WarpResidualOptions {
  double residual_px = 2.5;   // moving if residual > residual_px + residual_rel·|flow|
  double residual_rel = 0.08;
  double mismatch_px = 1e9;   // residual above this: a wrong correspondence, no evidence (kMismatch)
  // Optional, per point: residual_px is multiplied by it (keypoint positions from coarse pyramid
  // levels are less precise than tracked ones).
  const std::vector<float>* tolerance_scale = nullptr;
  double depth_abs_m = 0.03;  // depth moving if |z_pred − z_prev| > abs + rel·z² (3×3 min)
  double depth_rel = 0.01;
  float max_depth_m = 8.f;
};
struct WarpResidualResult {
  std::vector<float> residual_px;    // per point, −1 when not computable (no depth / invalid)
  std::vector<CueVote> residual;     // reprojection vote
  std::vector<CueVote> depth;        // depth-consistency vote
};
WarpResidualResult WarpResidualCue(const PinholeCamera& camera, const Rigid3d& prev_from_cur,
                                   const std::vector<cv::Point2f>& p1, const std::vector<cv::Point2f>& p2,
                                   const std::vector<uint8_t>& valid, const cv::Mat& depth_cur,
                                   const cv::Mat& depth_prev, const WarpResidualOptions& options);

}  // namespace dynorb
