// Pose-only optimisation (motion-only BA) of one frame against known 3-D points, as ORB-SLAM2's
// tracking does it: minimise  sum_i rho( r_i^T r_i )  over cam_from_world, where r_i is the
// reprojection residual of reprojection_cost.h (2-D for monocular, 3-D for RGB-D observations)
// and rho is Huber with threshold sqrt(chi2 gate). `num_rounds` rounds of `iterations_per_round`
// Levenberg-Marquardt iterations; after each round every observation is re-classified by its
// chi^2 against the gate (5.991 for 2 dof, 7.815 for 3 dof: 95 %), outliers are excluded from
// the next round, and the robust kernel is dropped for the last rounds.
// Provisional observations (landmarks the map has not confirmed yet, e.g. created from depth by
// the previous keyframe) take no part in the robust rounds when at least `min_established`
// established observations exist: the pose comes from the established map first, and a
// provisional observation joins the plain rounds only if it agrees with that pose (chi^2 gate).
// A mover that a keyframe turned into fresh landmarks thus cannot pull the next frame's pose by
// up to a gate's width per point; in a static scene the fresh points still refine the pose.
// The gates adapt to the measured keypoint noise (min_gate_scale below): this benchmark's keypoints
// are localised to ~0.5 px, where the 1-px gates let slightly wrong matches and slow movers in.
// Stateless and thread-safe; deterministic (single-threaded Ceres).
#pragma once

#include <optional>
#include <vector>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/optimization/reprojection_cost.h"

namespace ceres {
class CostFunction;
}

namespace dynorb {

struct PoseOptimizerOptions {
  int num_rounds = 4;               // Outlier re-classification rounds.
  int iterations_per_round = 10;    // LM iterations per round.
  int robust_rounds = 2;            // Rounds that use the Huber kernel (the rest are plain L2).
  double chi2_mono = 5.991;         // 95 % chi^2 gate, 2 dof.
  double chi2_stereo = 7.815;       // 95 % chi^2 gate, 3 dof.
  int min_established = 50;         // Fewer established observations: provisional ones count fully.
  // Provisional observations join only within this fraction of the chi^2 gate (0.25: half the
  // pixel distance). Measured over 12 dynamic sequences: mean ATE 5.87 -> 5.40 mm, twins 5.46 -> 4.79.
  double provisional_gate_factor = 0.25;
  // Gates that follow the keypoints' measured noise. The chi^2 gates above assume sigma = 1 px at
  // level 0 (ORB-SLAM2); after the first round the variance is estimated from the observations
  // inside those gates (median of chi^2 over the median of chi^2 with their dof), and the gates
  // and Huber widths of the later rounds are scaled by it, clamped to [min_gate_scale, 1].
  // 1 = fixed gates (ORB-SLAM2). Measured on 12 dynamic sequences (docs/results.md, session 27).
  double min_gate_scale = 0.3;
  // An RGB-D observation in the disparity form (KeypointObservation::disparity_information > 0)
  // outside its 3-dof gate whose pixel alone is inside the 2-dof gate joins as a monocular one:
  // its depth sample is off (a depth edge: the keypoint on the background, the depth from the
  // person in front), its pixel is still good. false = ORB-SLAM2 (dropped whole), the default:
  // measured mixed (docs/results.md, session 28: 300-frame cuts semantic -7.2 %, full length +4.5
  // %).
  bool depth_fallback = false;
  void Validate() const;            // Throws InputError on nonsense values.
};

// Optional prior on where the camera is (its centre in the world frame), e.g. a smoothed
// motion model's prediction: residual (centre(cam_from_world) - centre_in_world) / sigma_m, in the
// chi^2 units of the reprojection residuals, behind a Huber kernel at `huber_sigmas`. It takes
// part in every round and is never an outlier. Where the points pin the pose it changes almost
// nothing; it damps the directions they leave loose (a sideways shift traded against a turn when
// the near structure is hidden).
struct CentrePrior {
  Eigen::Vector3d centre_in_world = Eigen::Vector3d::Zero();
  double sigma_m = 0.001;
  double huber_sigmas = 3.0;
};

// The prior's cost (3 residuals on the pose block of pose_block.h), for solvers and tests; the
// caller or a ceres::Problem takes ownership.
ceres::CostFunction* NewCentrePriorCost(const CentrePrior& prior);

struct PoseObservation {
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  KeypointObservation keypoint;
  bool provisional = false;  // Unconfirmed landmark: must agree with the established pose first.
};

struct PoseOptimizerResult {
  Rigid3d cam_from_world;
  std::vector<bool> inlier;  // One flag per observation.
  int num_inliers = 0;
  double gate_scale = 1.0;  // The gates' scale after the first round (see min_gate_scale).
  // Per observation: inside the unscaled (1-px) gates at the final pose, as ORB-SLAM2 would count
  // it. The tracker's keyframe rule counts these, so that tighter gates do not make keyframes.
  std::vector<bool> nominal_inlier;
  // Per observation: an inlier through its pixel only (depth_fallback), its depth left out.
  std::vector<bool> depth_dropped;
};

// The noise variance (in units of the observations' nominal sigma^2) estimated from chi^2 values
// of observations with `dof` 2 or 3: the median of chi2_i / median(chi^2_{dof_i}). nullopt with
// fewer than 20 values. Exposed for tests.
std::optional<double> EstimateNoiseScale(const std::vector<double>& chi2,
                                         const std::vector<int>& dof);

PoseOptimizerResult OptimizePose(const PinholeCamera& camera, double bf,
                                 const std::vector<PoseObservation>& observations,
                                 const Rigid3d& initial_cam_from_world,
                                 const PoseOptimizerOptions& options = {},
                                 const CentrePrior* prior = nullptr);

// Plain least-squares refinement (no robust kernel, no outlier rounds, unit weights) of
// cam_from_world from the monocular pixels of points given in world coordinates:
// Levenberg–Marquardt from the initial pose, at most max_iterations (>= 1) iterations (fewer once
// converged by Ceres' default tolerances), all points
// in one residual block (cheap enough to call tens of times per frame: the FAST filter's
// ego-motion). std::nullopt with fewer than 3 points or when the solver gives no usable finite
// result. One pixel per point (checked, aborts). Deterministic.
std::optional<Rigid3d> RefinePoseLeastSquares(const PinholeCamera& camera,
                                              std::vector<Eigen::Vector3d> points_in_world,
                                              const std::vector<Eigen::Vector2d>& pixels,
                                              const Rigid3d& initial_cam_from_world,
                                              int max_iterations);

}  // namespace dynorb
