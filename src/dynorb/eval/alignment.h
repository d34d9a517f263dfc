// Closed-form alignment of estimated positions to ground-truth positions (least squares):
//
//   min over (s, R, t) of  sum_i || gt_i - (s R est_i + t) ||^2
//
// se3: s = 1 (RGB-D, stereo); sim3: s free (monocular); none: identity. Solved with
// Eigen::umeyama (Umeyama, PAMI 1991), which gives the same minimiser as Horn's closed form
// (Horn, JOSA A 1987) used by TUM's evaluate_ate.py; the tests check the two agree.
// Pure functions, thread-safe.
#pragma once

#include <Eigen/Core>
#include <string>

namespace dynorb {

enum class AlignmentMode { kSe3, kSim3, kNone };

// "se3" | "sim3" | "none"; throws InputError naming the accepted values otherwise.
AlignmentMode ParseAlignmentMode(const std::string& text);
std::string ToString(AlignmentMode mode);

// gt_from_est: maps an estimate-world point into the ground-truth world, p_gt = s R p_est + t.
struct Similarity3d {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const {
    return scale * (rotation * p) + translation;
  }
};

// Columns are corresponding points. Needs >= 3 points for se3/sim3 (throws InputError). Also
// throws InputError when the estimate positions have no spread (rms distance to their mean at
// most 1e-12 of their largest coordinate: one point, wherever it lies), and for sim3 when the
// ground-truth positions have none or do not correlate with the estimate (scale ~0). se3 with a
// ground truth that has no spread is defined (any rotation gives the same errors).
Similarity3d AlignPositions(const Eigen::Matrix3Xd& est_positions,
                            const Eigen::Matrix3Xd& gt_positions, AlignmentMode mode);

}  // namespace dynorb
