// Synthetic ground-truth / estimate trajectory pairs for exercising the evaluator
// (`dynorb trajgen`, tests, benchmarks). Deterministic for a seed on every platform: the random
// numbers come from std::mt19937_64 (fully specified by the standard) with our own Box-Muller.
//
// Ground truth: a smooth hand-held-like path (sums of slow sinusoids, ~1 m extent) with a
// camera orientation that pans and tilts, sampled at rate_hz from t0 = 1.3e9 s.
// Estimate: the same path seen in another world frame,
//   est_world_from_cam(t) = est_from_gt_world * [scale, drift, noise](gt_world_from_cam(t)),
// where positions get a linear drift (drift_m_per_s along a fixed random direction), Gaussian
// noise (sigma noise_m per axis) and are multiplied by `scale`; orientations get Gaussian noise
// (sigma noise_m radians per axis). Estimate stamps are the ground-truth stamps plus a few
// milliseconds of jitter; about drop_fraction of the frames are dropped.
#pragma once

#include <cstdint>

#include "dynorb/core/rigid3.h"
#include "dynorb/core/trajectory.h"

namespace dynorb {

struct TrajectoryPairOptions {
  uint64_t seed = 1;              // random seed
  double duration_s = 30.0;       // length of the ground truth
  double rate_hz = 30.0;          // pose rate of ground truth and estimate
  double noise_m = 0.01;          // position noise sigma per axis (m); orientation sigma (rad)
  double drift_m_per_s = 0.002;   // linear position drift of the estimate
  double scale = 1.0;             // estimate scale (monocular-like when != 1)
  double drop_fraction = 0.02;    // fraction of estimate frames dropped
  double stamp_jitter_s = 0.003;  // estimate stamps differ from ground truth by up to this
                                  // (capped at a quarter frame interval)
  void Validate() const;          // throws InputError
};

struct TrajectoryPair {
  Trajectory groundtruth;
  Trajectory estimate;
  Rigid3d est_world_from_gt_world;  // the rigid frame change applied to the estimate
};

TrajectoryPair GenerateTrajectoryPair(const TrajectoryPairOptions& options);

// Just the smooth ground-truth path (no estimate); used by benchmarks and tests.
Trajectory GenerateSmoothTrajectory(uint64_t seed, double duration_s, double rate_hz);

}  // namespace dynorb
