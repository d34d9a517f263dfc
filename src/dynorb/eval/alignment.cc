#include "dynorb/eval/alignment.h"

#include <Eigen/Geometry>
#include <cmath>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

// A spread (root-mean-square distance to the mean) at or below this fraction of the largest
// coordinate is rounding noise: the points are one point (1e-12 ~ 5000 ulp of a double).
constexpr double kMinRelativeSpread = 1e-12;
// sim3: below this correlation between the point sets the scale is rounding noise (~0).
constexpr double kMinCorrelation = 1e-9;

// Root of the summed squared distances of the points to their mean.
double Spread(const Eigen::Matrix3Xd& points) {
  return std::sqrt((points.colwise() - points.rowwise().mean()).squaredNorm());
}

// Relative to the coordinates' magnitude: 500 identical points at (5e5, 5.4e6, 100) have none.
bool HasSpread(double spread, const Eigen::Matrix3Xd& positions) {
  const double rms_spread = spread / std::sqrt(static_cast<double>(positions.cols()));
  return rms_spread > kMinRelativeSpread * positions.cwiseAbs().maxCoeff();
}

}  // namespace

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
  // Relative to the first point: identical points give exact zeros, and coordinates far from the
  // origin (e.g. UTM, ~5e6 m) lose no precision in the sums of the solver.
  const Eigen::Vector3d est_origin = est_positions.col(0), gt_origin = gt_positions.col(0);
  const Eigen::Matrix3Xd est = est_positions.colwise() - est_origin;
  const Eigen::Matrix3Xd gt = gt_positions.colwise() - gt_origin;
  const double est_spread = Spread(est), gt_spread = Spread(gt);
  if (!HasSpread(est_spread, est_positions)) {
    throw InputError(
        "alignment: all associated estimate positions are identical; use --align none");
  }
  const bool with_scale = mode == AlignmentMode::kSim3;
  const char* const no_sim3 =
      "alignment: the ground-truth positions have no spread, or do not correlate with the "
      "estimate: no sim3 alignment (use --align se3 or none)";
  if (with_scale && !HasSpread(gt_spread, gt_positions)) throw InputError(no_sim3);
  const Eigen::Matrix4d m = Eigen::umeyama(est, gt, with_scale);
  const Eigen::Matrix3d scaled_rotation = m.topLeftCorner<3, 3>();
  if (with_scale) {
    // The columns of s R have length s. s * spread(est) / spread(gt) is the correlation of the
    // two point sets under the best rotation, in [0, 1]: ~0 leaves the scale (and R) undefined.
    gt_from_est.scale = scaled_rotation.col(0).norm();
    if (!(gt_from_est.scale * est_spread > kMinCorrelation * gt_spread)) throw InputError(no_sim3);
  }
  gt_from_est.rotation = scaled_rotation / gt_from_est.scale;
  // gt - gt_origin = s R (est - est_origin) + t'  =>  t = t' + gt_origin - s R est_origin.
  gt_from_est.translation = m.topRightCorner<3, 1>() + gt_origin -
                            gt_from_est.scale * (gt_from_est.rotation * est_origin);
  return gt_from_est;
}

}  // namespace dynorb
