#include "dynorb/eval/ate.h"

#include "dynorb/core/error.h"

namespace dynorb {

AteResult ComputeAte(const Trajectory& gt, const Trajectory& est,
                     const std::vector<IndexPair>& pairs, AlignmentMode mode) {
  if (pairs.empty()) throw InputError("ATE: no associated pose pairs");
  const Eigen::Index n = static_cast<Eigen::Index>(pairs.size());
  Eigen::Matrix3Xd est_positions(3, n), gt_positions(3, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    est_positions.col(k) = est[pairs[k].est].world_from_cam.translation;
    gt_positions.col(k) = gt[pairs[k].gt].world_from_cam.translation;
  }
  AteResult result;
  result.mode = mode;
  result.pairs = pairs;
  result.gt_from_est = AlignPositions(est_positions, gt_positions, mode);
  result.errors_m.resize(pairs.size());
  for (Eigen::Index k = 0; k < n; ++k) {
    result.errors_m[k] =
        (gt_positions.col(k) - result.gt_from_est * Eigen::Vector3d(est_positions.col(k))).norm();
  }
  result.stats = Summarize(result.errors_m);
  return result;
}

}  // namespace dynorb
