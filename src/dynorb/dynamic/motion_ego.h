// Ego-motion of the camera between the previous and the current frame, for the FAST dynamic
// mode: the pose prev_from_cur that maps current points (back-projected with the current depth)
// onto their tracked positions in the previous frame, x1 ≈ π(prev_from_cur · π⁻¹(x2, z2)).
//
// Hypotheses are refined by iterative re-weighting: keep the points whose residual under the
// current estimate is below a shrinking gate (5 → 3 → 2 px), refit (least-squares pose fit,
// RefinePoseLeastSquares, on those; skipped when the gate keeps the same points), repeat; then
// the gate follows the data: gate_sigmas × the robust spread (1.4826 × median) of the inliers'
// residuals, at least min_gate_px, refit again. The tight gate
// matters: a hypothesis that explains the background and a walking person together ("the camera
// moved 6 cm and turned 1°" instead of "1 cm") fits most points within 2 px, but only the true
// motion fits the background to the tracking noise (≈ 0.1 px on synthetic data). Hypotheses:
// seeds (predictions, in priority order: the tracker's motion model, the filter's own chain), the
// camera at rest (identity), and two PnP-RANSAC hypotheses (fixed seed: the dominant motion and
// the dominant motion of its outliers). All are scored at one common gate (from the smallest
// spread among them) by coverage: the fraction of the grid cells holding tracked points that hold
// inliers (a cell counts when at least half of its points are inliers). The scoring gate may be
// tighter than the refinement's (score_min_gate_px < min_gate_px): on synthetic data the static
// background fits to ~0.1 px, while a walking person filling half of the view fits a rigid motion
// only to ~0.25 px; at a 0.5 px gate both cover their cells and the person, larger, wins over a
// correct prediction (full-length walking_xyz s7, frames 825-830, session 12).
// When a prediction alone fits to the noise floor (3 sigmas within skip_search_gate_px) and covers
// skip_search_coverage of the cells there, the camera-at-rest and RANSAC hypotheses are not tried
// (they cost most of the time). The 0.8 px gate fits the noise of LK with an 11 px window on
// synthetic data (robust spread about 0.2 px: scoring gates of 0.57-0.63 px, median). The 0.5 px
// of before (set for 21 px windows) let the search run in 23-92 % of the frames; with 0.8 px all
// 24 evaluation trajectories stayed byte-identical (session 18).
// The first seed (not the camera at rest) whose coverage is at least min_seed_coverage and whose
// coverage and inlier count are at least seed_coverage_ratio × the best ones wins — on a near-tie
// the prediction decides, so a mover about as large as the visible background cannot capture the
// estimate. A seed with min_seed_coverage also wins when it fits more rigidly than every hypothesis
// that covers more of the image (their spread sigma >= seed_rigidity_ratio × its own): a walking
// person filling more than half of the view fits a rigid motion about twice as loosely as the
// static background does (full-length walking_xyz s7, frames 825-829: 0.22-0.26 against 0.13 px),
// whatever the gate. Otherwise (start, lost, a prediction that follows a mover) the hypothesis
// covering most of the image wins (the static background is spread over the image), more inliers
// breaking a tie. Pure function; thread-safe.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"

namespace dynorb {

struct EgoMotionOptions {
  std::vector<double> gates_px = {5.0, 3.0, 2.0};  // shrinking inlier gates of the refinement
  double gate_sigmas = 3.0;     // then the gate is this many robust sigmas of the inlier residuals
  double min_gate_px = 0.5;     // ... but at least this (px)
  double score_min_gate_px = 0.3;  // floor of the common scoring gate (3 sigmas of the tightest fit)
  int adaptive_iterations = 2;  // refits with the adaptive gate
  bool try_identity = true;     // also refine "the camera did not move"
  int max_fit_points = 150;     // each refit uses at most this many inliers (evenly strided; 0: all)
  int lm_iterations = 5;        // at most this many Levenberg–Marquardt iterations per refit
  int min_points = 12;          // fewer inliers: keep the previous estimate / fail
  double ransac_px = 3.0;       // PnP-RANSAC threshold (no prediction)
  int ransac_iterations = 200;  // PnP-RANSAC iterations (no prediction)
  float max_depth_m = 8.f;      // ignore depth beyond this
  bool refine = true;           // false: return the first seed as is (when given)
  double min_seed_coverage = 0.25;  // seed accepted if its inliers cover this fraction of cells
  double seed_coverage_ratio = 0.9;  // ... and coverage and inliers >= this fraction of the best
  double seed_rigidity_ratio = 1.5;  // ... or every hypothesis covering more fits this many times
                                     // more loosely (sigma; 0: off)
  int grid_cols = 8, grid_rows = 6;  // coverage grid
  double skip_search_coverage = 0.6;  // a prediction covering this much ...
  double skip_search_gate_px = 0.8;   // ... at a scoring gate of at most this (px): no search
  double duplicate_seed_m = 0.002;    // a prediction this close to a refined one is not refined again
  double duplicate_seed_rad = 0.001;  // (translation and rotation)
  bool abandon_duplicate_predictions = true;  // ... nor refined on when its first refit lands there
};

struct EgoMotionResult {
  bool ok = false;
  int seed_index = -1;  // the accepted seed, -1: RANSAC hypothesis, -2: the camera at rest
  Rigid3d prev_from_cur;
  int num_inliers = 0;  // points within gate_px (the common scoring gate)
  double coverage = 0.0;  // fraction of occupied cells covered by inliers
  double sigma_px = 0.0;  // robust spread of the inliers' residuals (px)
  double gate_px = 0.0;   // the common gate the hypotheses were scored at (px)
  bool searched = false;  // the camera-at-rest and RANSAC hypotheses were tried
  int hypotheses = 0;     // hypotheses refined to the end and voted on
};

// The tracked points that vote for the ego-motion: valid[i] != 0 and p1[i] (the point's position
// in the previous frame) outside previous_mask (the previous frame's dynamic regions, CV_8U; empty:
// none). A mover that fills much of the view fits a rigid motion of its own and can win the
// coverage vote; the last frame already found it. When more than max_fraction of the valid points
// would be left out, the previous regions are suspect themselves: all valid points vote.
std::vector<uint8_t> EgoMotionVoters(const std::vector<uint8_t>& valid,
                                     const std::vector<cv::Point2f>& p1,
                                     const cv::Mat& previous_mask, double max_fraction);

EgoMotionResult EstimateEgoMotion(const PinholeCamera& camera, const std::vector<cv::Point2f>& p1,
                                  const std::vector<cv::Point2f>& p2, const std::vector<uint8_t>& valid,
                                  const cv::Mat& depth_cur, const std::vector<Rigid3d>& seeds_prev_from_cur,
                                  const EgoMotionOptions& options);

// EstimateEgoMotion with the previous frame's dynamic regions as a prior: when a hypothesis other
// than a prediction wins (the prediction was outvoted), the vote is repeated without the points
// in previous_mask (EgoMotionVoters); if a prediction wins that vote, it is the result. A mover
// that fills much of the view, found by the previous frame, cannot capture the estimate; the
// prior is not used when the prediction wins anyway (a wrong previous region cannot hold).
// always (session 23): the points in previous_mask never vote (EgoMotionVoters), whoever wins;
// the vote above runs only if that estimate fails. A slow mover that the prediction partly
// follows then cannot pull the refits towards its motion once it has been found.
EgoMotionResult EstimateEgoMotionWithPrior(
    const PinholeCamera& camera, const std::vector<cv::Point2f>& p1,
    const std::vector<cv::Point2f>& p2, const std::vector<uint8_t>& valid, const cv::Mat& depth_cur,
    const std::vector<Rigid3d>& seeds_prev_from_cur, const cv::Mat& previous_mask,
    double max_fraction, const EgoMotionOptions& options, bool always = false);

}  // namespace dynorb
