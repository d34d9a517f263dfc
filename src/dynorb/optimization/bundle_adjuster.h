// Bundle adjustment of keyframe poses and landmark positions (local BA of the mapper, or a
// global BA): minimise  sum_obs rho( r^T r )  over the free cam_from_world poses and all points,
// with r the reprojection residual of reprojection_cost.h and rho Huber(sqrt(chi2 gate)).
// As in ORB-SLAM2's local BA: a first robust solve, then observations whose chi^2 exceeds the
// gate (or whose point is behind the camera) are excluded and a second solve runs without them.
// Fixed keyframes anchor the gauge. Points are eliminated with the Schur complement.
// Stateless and thread-safe; deterministic (single-threaded Ceres).
#pragma once

#include <atomic>
#include <cstddef>
#include <vector>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/optimization/reprojection_cost.h"

namespace dynorb {

struct BundleAdjusterOptions {
  int first_iterations = 5;    // LM iterations with all observations (robust).
  int second_iterations = 10;  // LM iterations after excluding outliers.
  double chi2_mono = 5.991;
  double chi2_stereo = 7.815;
  // Reduced camera systems with more free keyframes than this are factorised sparsely (a global
  // BA over a whole map); a local window's is small and dense. BM_GlobalBundleAdjustment: the same
  // time at 30 keyframes, sparse 7-10 % faster at 60-120.
  int dense_max_keyframes = 60;
  // When set, the solve ends after the iteration during which it became true (the result is then
  // not converged and should be discarded).
  const std::atomic<bool>* stop = nullptr;
  void Validate() const;
};

struct BaKeyframe {
  Rigid3d cam_from_world;
  bool fixed = false;
};

struct BaObservation {
  size_t keyframe_index = 0;
  size_t landmark_index = 0;
  KeypointObservation keypoint;
};

struct BundleAdjusterResult {
  std::vector<Rigid3d> cam_from_world;        // Per keyframe (fixed ones unchanged).
  std::vector<Eigen::Vector3d> points_in_world;
  std::vector<bool> observation_inlier;       // Per observation, after the final solve.
  double initial_cost = 0.0;
  double final_cost = 0.0;
  bool converged = false;  // every stage ran and left a usable solution (Ceres' judgement)
  bool stopped = false;    // BundleAdjusterOptions::stop ended it.
  bool failed = false;     // a stage ended without a usable solution (Ceres' judgement, e.g. a
                           // non-finite residual): the values are not to be committed
};

BundleAdjusterResult RunBundleAdjustment(const PinholeCamera& camera, double bf,
                                         const std::vector<BaKeyframe>& keyframes,
                                         const std::vector<Eigen::Vector3d>& points_in_world,
                                         const std::vector<BaObservation>& observations,
                                         const BundleAdjusterOptions& options = {});

}  // namespace dynorb
