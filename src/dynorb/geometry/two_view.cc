#include "dynorb/geometry/two_view.h"

#include <cmath>
#include <limits>

#include <Eigen/SVD>

namespace dynorb {

std::optional<Eigen::Vector3d> TriangulateDlt(const Rigid3d& cam1_from_world, const Eigen::Vector2d& normalized1,
                                              const Rigid3d& cam2_from_world, const Eigen::Vector2d& normalized2) {
  const Eigen::Matrix<double, 3, 4> p1 = cam1_from_world.ToMatrix3x4();
  const Eigen::Matrix<double, 3, 4> p2 = cam2_from_world.ToMatrix3x4();
  Eigen::Matrix4d a;
  a.row(0) = normalized1.x() * p1.row(2) - p1.row(0);
  a.row(1) = normalized1.y() * p1.row(2) - p1.row(1);
  a.row(2) = normalized2.x() * p2.row(2) - p2.row(0);
  a.row(3) = normalized2.y() * p2.row(2) - p2.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(a, Eigen::ComputeFullV);
  const Eigen::Vector4d x = svd.matrixV().col(3);
  if (std::abs(x.w()) < 1e-12) return std::nullopt;
  return Eigen::Vector3d(x.head<3>() / x.w());
}

Eigen::Matrix3d FundamentalFromPoses(const PinholeCamera& camera, const Rigid3d& cam1_from_world,
                                     const Rigid3d& cam2_from_world) {
  return FundamentalFromMotion(camera, cam2_from_world * cam1_from_world.Inverse());
}

Eigen::Matrix3d FundamentalFromMotion(const PinholeCamera& camera, const Rigid3d& cam2_from_cam1) {
  const Eigen::Vector3d& t = cam2_from_cam1.translation;
  Eigen::Matrix3d skew;
  skew << 0.0, -t.z(), t.y(), t.z(), 0.0, -t.x(), -t.y(), t.x(), 0.0;
  const Eigen::Matrix3d k_inv = camera.K().inverse();
  return k_inv.transpose() * skew * cam2_from_cam1.rotation.toRotationMatrix() * k_inv;
}

double EpipolarDistancePx(const Eigen::Matrix3d& f21, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2) {
  const Eigen::Vector3d line = f21 * x1.homogeneous();
  const double norm = std::hypot(line.x(), line.y());
  if (norm < 1e-12) return std::numeric_limits<double>::infinity();
  return std::abs(line.dot(x2.homogeneous())) / norm;
}

}  // namespace dynorb
