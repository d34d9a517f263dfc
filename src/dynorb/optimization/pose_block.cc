#include "dynorb/optimization/pose_block.h"

#include <cmath>

#include <ceres/manifold.h>

namespace dynorb {
namespace {

Eigen::Quaterniond ExpSO3(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  if (theta < 1e-10) return Eigen::Quaterniond(1.0, 0.5 * omega.x(), 0.5 * omega.y(), 0.5 * omega.z()).normalized();
  const Eigen::Vector3d axis = omega / theta;
  return Eigen::Quaterniond(Eigen::AngleAxisd(theta, axis));
}

Eigen::Vector3d LogSO3(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double vn = q.vec().norm();
  if (vn < 1e-10) return 2.0 * q.vec();
  return 2.0 * std::atan2(vn, q.w()) * q.vec() / vn;
}

// See pose_block.h for the parameterisation.
class PoseManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseBlockSize; }
  int TangentSize() const override { return kPoseTangentSize; }

  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    for (int i = 0; i < 3; ++i) x_plus_delta[i] = x[i] + delta[i];
    const Eigen::Quaterniond q(x[6], x[3], x[4], x[5]);
    const Eigen::Quaterniond q_new = (q * ExpSO3(Eigen::Vector3d(delta[3], delta[4], delta[5]))).normalized();
    x_plus_delta[3] = q_new.x();
    x_plus_delta[4] = q_new.y();
    x_plus_delta[5] = q_new.z();
    x_plus_delta[6] = q_new.w();
    return true;
  }

  bool PlusJacobian(const double* /*x*/, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> j(jacobian);
    j.setZero();
    j.topRows<6>().setIdentity();
    return true;
  }

  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    for (int i = 0; i < 3; ++i) y_minus_x[i] = y[i] - x[i];
    const Eigen::Quaterniond qx(x[6], x[3], x[4], x[5]);
    const Eigen::Quaterniond qy(y[6], y[3], y[4], y[5]);
    const Eigen::Vector3d w = LogSO3(qx.conjugate() * qy);
    y_minus_x[3] = w.x();
    y_minus_x[4] = w.y();
    y_minus_x[5] = w.z();
    return true;
  }

  bool MinusJacobian(const double* /*x*/, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> j(jacobian);
    j.setZero();
    j.leftCols<6>().setIdentity();
    return true;
  }
};

}  // namespace

PoseBlock ToPoseBlock(const Rigid3d& cam_from_world) {
  const Eigen::Quaterniond q = cam_from_world.rotation.normalized();
  const Eigen::Vector3d& t = cam_from_world.translation;
  return {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
}

Rigid3d FromPoseBlock(const double* block) {
  return Rigid3d(Eigen::Quaterniond(block[6], block[3], block[4], block[5]),
                 Eigen::Vector3d(block[0], block[1], block[2]));
}

ceres::Manifold* NewPoseManifold() { return new PoseManifold(); }

}  // namespace dynorb
