// Coverage: how much of the ground-truth time span the associated estimate poses cover, so that
// a system that drops hard frames (or loses tracking) cannot look better silently.
//
//   span     = [t_gt_first, t_gt_last]
//   covered  = span ∩ union over associated estimate poses k of [s_k - window_s, s_k + window_s],
//              s_k = t_est_k + offset_s (the estimate stamp on the ground-truth clock)
//   fraction = |covered| / |span|
//
// With the default window of 0.05 s, one missing frame of a 30 Hz camera (a 67 ms gap) costs
// nothing, while a gap of G seconds costs G - 0.1 s, and a late start or early end costs its
// duration. Only associated poses count: an estimate with no ground truth within max_diff covers
// nothing. Pure functions, thread-safe.
#pragma once

#include <vector>

#include "dynorb/core/trajectory.h"
#include "dynorb/eval/association.h"

namespace dynorb {

struct CoverageOptions {
  double window_s = 0.05;  // each associated estimate pose covers +-window_s of ground-truth time
  double offset_s = 0.0;   // added to estimate stamps (same as the association offset)
  void Validate() const;   // throws InputError
};

struct Coverage {
  double fraction = 0.0;             // |covered| / |span| in [0, 1]
  double gt_begin_s = 0.0;           // t_gt_first
  double gt_span_s = 0.0;            // t_gt_last - t_gt_first
  double covered_s = 0.0;            // |covered|
  double longest_gap_s = 0.0;        // longest uncovered interval inside the span
  double longest_gap_start_s = 0.0;  // its start (ground-truth clock)
};

Coverage ComputeCoverage(const Trajectory& gt, const Trajectory& est,
                         const std::vector<IndexPair>& pairs, const CoverageOptions& options);

}  // namespace dynorb
