// Timestamp association of an estimated trajectory with ground truth, with the rule of the TUM
// RGB-D benchmark's associate.py (Sturm et al., IROS 2012):
//
//   candidates = all (gt i, est j) with |t_gt[i] - (t_est[j] + offset_s)| < max_diff_s
//   sort candidates by (difference, t_gt, t_est); accept greedily if neither pose is used yet;
//   return the accepted pairs sorted by ground-truth stamp.
//
// Computed by core/stamp_association.h (shared with the dataset reader) after checking that both
// stamp lists are strictly increasing.
// Pure functions, thread-safe.
#pragma once

#include <vector>

#include "dynorb/core/trajectory.h"

namespace dynorb {

struct StampAssociationOptions {
  double max_diff_s = 0.02;  // a match needs |t_gt - (t_est + offset_s)| < max_diff_s (strict)
  double offset_s = 0.0;     // added to every estimate stamp before matching (estimate delay)
  void Validate() const;     // throws InputError
};

struct IndexPair {
  int gt = 0;   // index into the ground-truth trajectory
  int est = 0;  // index into the estimated trajectory
  bool operator==(const IndexPair& o) const { return gt == o.gt && est == o.est; }
};

// Stamps must be strictly increasing (throws InputError otherwise).
std::vector<IndexPair> AssociateStamps(const std::vector<double>& gt_stamps_s,
                                       const std::vector<double>& est_stamps_s,
                                       const StampAssociationOptions& options);
std::vector<IndexPair> AssociateTrajectories(const Trajectory& gt, const Trajectory& est,
                                             const StampAssociationOptions& options);

std::vector<double> Stamps(const Trajectory& trajectory);

}  // namespace dynorb
