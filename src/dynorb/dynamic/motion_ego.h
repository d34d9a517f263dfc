// Ego-motion of the camera between the previous and the current frame, for the FAST dynamic
// mode: the pose prev_from_cur that maps current points (back-projected with the current depth)
// onto their tracked positions in the previous frame, x1 ≈ π(prev_from_cur · π⁻¹(x2, z2)).
//
// Hypotheses are refined by iterative re-weighting: keep the points whose residual under the
// current estimate is below a shrinking gate (5 → 3 → 2 px), refit (Levenberg–Marquardt
// PnP on those), repeat. Seeds (predictions, in priority order: the filter's own constant-velocity
// model, then the filter's own chain) and two PnP-RANSAC hypotheses (fixed seed: the dominant
// motion and the dominant motion of its outliers) are refined and scored by coverage: the fraction
// of the grid cells holding tracked points that hold inliers. The first seed whose coverage is at
// least min_seed_coverage and seed_coverage_ratio × the best coverage wins — its inlier set is
// defined by the prediction, not by a majority vote, so a mover covering up to about half of the
// image cannot capture it; otherwise (start, lost, a prediction that follows a mover) the
// hypothesis covering most of the image wins (the static background is spread over the image).
// Pure function; thread-safe.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"

namespace dynorb {

struct EgoMotionOptions {
  std::vector<double> gates_px = {5.0, 3.0, 2.0};  // shrinking inlier gates of the refinement
  int min_points = 12;          // fewer inliers: keep the previous estimate / fail
  double ransac_px = 3.0;       // PnP-RANSAC threshold (no prediction)
  int ransac_iterations = 200;  // PnP-RANSAC iterations (no prediction)
  float max_depth_m = 8.f;      // ignore depth beyond this
  bool refine = true;           // false: return the first seed as is (when given)
  double min_seed_coverage = 0.25;  // seed accepted if its inliers cover this fraction of cells
  double seed_coverage_ratio = 0.6;  // ... and at least this fraction of the best hypothesis'
  int grid_cols = 8, grid_rows = 6;  // coverage grid
};

struct EgoMotionResult {
  bool ok = false;
  int seed_index = -1;  // the accepted seed, -1: RANSAC hypothesis
  Rigid3d prev_from_cur;
  int num_inliers = 0;  // points within the last gate
  double coverage = 0.0;  // fraction of occupied cells covered by inliers
};

EgoMotionResult EstimateEgoMotion(const PinholeCamera& camera, const std::vector<cv::Point2f>& p1,
                                  const std::vector<cv::Point2f>& p2, const std::vector<uint8_t>& valid,
                                  const cv::Mat& depth_cur, const std::vector<Rigid3d>& seeds_prev_from_cur,
                                  const EgoMotionOptions& options);

}  // namespace dynorb
