// Absolute trajectory error (ATE) as defined by TUM's evaluate_ate.py (Sturm et al., IROS 2012):
// associate stamps (association.h), align the associated estimate positions to the ground-truth
// positions (alignment.h), and summarise the translational errors
//   e_i = || gt_i - (s R est_i + t) ||   over the associated pairs.
// Statistics: RMSE, mean, median, population std (numpy's default), min, max. Only positions
// enter ATE; orientations do not. Pure functions, thread-safe.
#pragma once

#include <vector>

#include "dynorb/core/stats.h"
#include "dynorb/core/trajectory.h"
#include "dynorb/eval/alignment.h"
#include "dynorb/eval/association.h"

namespace dynorb {

struct AteResult {
  AlignmentMode mode = AlignmentMode::kSe3;
  std::vector<IndexPair> pairs;  // associated pairs, sorted by ground-truth stamp
  Similarity3d gt_from_est;      // the alignment applied to the estimate
  std::vector<double> errors_m;  // e_i, one per pair (same order as pairs)
  SummaryStats stats;            // summary of errors_m (count = number of pairs)
};

// `pairs` from AssociateTrajectories(gt, est, ...). Throws InputError if there are no pairs, or
// fewer than 3 when aligning.
AteResult ComputeAte(const Trajectory& gt, const Trajectory& est,
                     const std::vector<IndexPair>& pairs, AlignmentMode mode);

}  // namespace dynorb
