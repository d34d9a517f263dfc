#include "dynorb/eval/alignment.h"

#include <Eigen/Geometry>
#include <cmath>

#include "dynorb/core/error.h"

namespace dynorb {

AlignmentMode ParseAlignmentMode(const std::string& text) {
  if (text == "se3") return AlignmentMode::kSe3;
  if (text == "sim3") return AlignmentMode::kSim3;
  if (text == "none") return AlignmentMode::kNone;
  throw InputError("unknown alignment '" + text + "' (expected se3, sim3 or none)");
}

std::string ToString(AlignmentMode mode) {
  switch (mode) {
    case AlignmentMode::kSe3:
      return "se3";
    case AlignmentMode::kSim3:
      return "sim3";
    case AlignmentMode::kNone:
      return "none";
  }
  return "?";
}

Similarity3d AlignPositions(const Eigen::Matrix3Xd& est_positions,
                            const Eigen::Matrix3Xd& gt_positions, AlignmentMode mode) {
  if (est_positions.cols() != gt_positions.cols())
    throw InputError("alignment: point count mismatch");
  Similarity3d gt_from_est;
  if (mode == AlignmentMode::kNone) return gt_from_est;
  if (est_positions.cols() < 3) {
    throw InputError("alignment needs at least 3 associated pose pairs, got " +
                     std::to_string(est_positions.cols()));
  }
  const Eigen::Vector3d mean = est_positions.rowwise().mean();
  if ((est_positions.colwise() - mean).squaredNorm() <= 1e-20) {
    throw InputError(
        "alignment: all associated estimate positions are identical; use --align none");
  }
  const bool with_scale = mode == AlignmentMode::kSim3;
  const Eigen::Matrix4d m = Eigen::umeyama(est_positions, gt_positions, with_scale);
  const Eigen::Matrix3d scaled_rotation = m.topLeftCorner<3, 3>();
  gt_from_est.scale = with_scale ? std::cbrt(scaled_rotation.determinant()) : 1.0;
  gt_from_est.rotation = scaled_rotation / gt_from_est.scale;
  gt_from_est.translation = m.topRightCorner<3, 1>();
  return gt_from_est;
}

}  // namespace dynorb
