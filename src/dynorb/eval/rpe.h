// Relative pose error (RPE) as computed by TUM's evaluate_rpe.py with
//   --fixed_delta --delta <delta_s> --delta_unit s --max_pairs 0   (all pairs, deterministic)
// (Sturm et al., IROS 2012), the setting papers report as "RPE per second":
//
//  1. Pairs (i, j) of ESTIMATE poses: for every estimate pose i, j is the estimate pose whose
//     stamp is closest to t_i + delta_s (exact ties broken as evaluate_rpe.py's bisection does,
//     see ClosestIndex). The pair is dropped when j is the last estimate pose (evaluate_rpe.py's
//     rule for "t_i + delta beyond the end"), and, unlike evaluate_rpe.py, when j = i (delta_s
//     shorter than about half the frame interval): a pose paired with itself has a 0 error.
//  2. Each of t_i, t_j is matched to its closest ground-truth stamp (closest to t + offset_s;
//     not one-to-one); the pair is dropped if either stamp difference exceeds
//     2 x the median ground-truth stamp interval.
//  3. With A = est_i^-1 est_j (translation multiplied by `scale`) and B = gt_i^-1 gt_j, the error
//     is E = A B^-1 — evaluate_rpe.py's ominus(ominus(est_j, est_i) scaled, ominus(gt_j, gt_i)).
//     Translational error |t(E)| (metres per delta), rotational error angle(R(E)).
//  The paper's formula E' = B^-1 A has the same angle; its translation |t(E')| = |t_A - t_B| is
//  reported alongside (trans_paper_form) because the two differ when rotations drift.
// Pure functions, thread-safe.
#pragma once

#include <string>
#include <vector>

#include "dynorb/core/stats.h"
#include "dynorb/core/trajectory.h"

namespace dynorb {

struct RpeOptions {
  double delta_s = 1.0;   // time between the two poses of a pair (seconds)
  double offset_s = 0.0;  // added to estimate stamps when matching ground truth
  double scale = 1.0;     // multiplies estimate translations (the sim3 scale, else 1)
  void Validate() const;  // throws InputError
};

struct RpePair {
  int est_i = 0, est_j = 0, gt_i = 0, gt_j = 0;
  double trans_m = 0.0;             // |t(A B^-1)|, evaluate_rpe.py
  double rot_rad = 0.0;             // angle(R(A B^-1)) = angle(R(B^-1 A))
  double trans_paper_form_m = 0.0;  // |t(B^-1 A)|
};

struct RpeResult {
  std::vector<RpePair> pairs;             // in order of est_i
  SummaryStats trans_m;                   // over pairs[].trans_m
  SummaryStats rot_deg;                   // over pairs[].rot_rad, in degrees
  SummaryStats trans_paper_form_m;        // over pairs[].trans_paper_form_m
  double gt_max_time_difference_s = 0.0;  // 2 x median ground-truth stamp interval
  // Why there is no pair when every candidate was a pose with itself (delta shorter than the
  // estimate's frame interval); empty otherwise.
  std::string no_pair_reason;
};

// Returns an empty result (count 0) if no pair qualifies, e.g. a trajectory shorter than delta;
// when delta_s is so short that every candidate pair is a pose with itself, `no_pair_reason`
// says so.
RpeResult ComputeRpe(const Trajectory& gt, const Trajectory& est, const RpeOptions& options);

// Index of the stamp closest to t in a sorted vector: evaluate_rpe.py's find_closest_index, a
// bisection that keeps the first visited stamp strictly closer than the best so far (index 0
// first). Exact ties depend on the bisection's path: {0, 1, 2} and 0.5 give 0, {0, 1, 2, 3} and
// 1.5 give 2.
size_t ClosestIndex(const std::vector<double>& sorted_stamps, double t);

}  // namespace dynorb
