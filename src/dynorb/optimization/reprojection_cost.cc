#include "dynorb/optimization/reprojection_cost.h"

#include <cmath>
#include <limits>

#include <ceres/cost_function.h>

#include "dynorb/optimization/pose_block.h"

namespace dynorb {
namespace {

constexpr double kMinDepth = 1e-6;

// Jacobians (d predicted / d point_in_cam), rows u, v, u_r:
//   [fx/z, 0, -fx x/z^2], [0, fy/z, -fy y/z^2], [fx/z, 0, -fx x/z^2 + bf/z^2].
// d point_in_cam / d dt = I,  d point_in_cam / d dtheta = -R [point_in_world]_x  (R <- R Exp(dtheta)),
// d point_in_cam / d point_in_world = R. The residual is observed - predicted, hence the minus.
class ReprojectionCost : public ceres::CostFunction {
 public:
  ReprojectionCost(const PinholeCamera& camera, double bf, const KeypointObservation& obs,
                   const Eigen::Vector3d* fixed_point)
      : camera_(camera), bf_(bf), obs_(obs), sqrt_info_(std::sqrt(obs.information)),
        has_fixed_point_(fixed_point != nullptr) {
    if (has_fixed_point_) fixed_point_ = *fixed_point;
    set_num_residuals(obs.IsStereo() ? 3 : 2);
    mutable_parameter_block_sizes()->push_back(kPoseBlockSize);
    if (!has_fixed_point_) mutable_parameter_block_sizes()->push_back(3);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* pose = parameters[0];
    const Eigen::Quaterniond q(pose[6], pose[3], pose[4], pose[5]);
    const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
    const Eigen::Vector3d t(pose[0], pose[1], pose[2]);
    const Eigen::Vector3d point_in_world =
        has_fixed_point_ ? fixed_point_ : Eigen::Vector3d(parameters[1][0], parameters[1][1], parameters[1][2]);
    const Eigen::Vector3d p = r * point_in_world + t;
    const double z = std::abs(p.z()) < kMinDepth ? (p.z() < 0 ? -kMinDepth : kMinDepth) : p.z();
    const double inv_z = 1.0 / z;
    const double u = camera_.fx * p.x() * inv_z + camera_.cx;
    const double v = camera_.fy * p.y() * inv_z + camera_.cy;
    const int n = num_residuals();
    residuals[0] = sqrt_info_ * (obs_.uv.x() - u);
    residuals[1] = sqrt_info_ * (obs_.uv.y() - v);
    if (n == 3) residuals[2] = sqrt_info_ * (obs_.u_right - (u - bf_ * inv_z));
    if (jacobians == nullptr) return true;

    // Fixed-size throughout: this runs for every residual at every iteration (no heap use).
    Eigen::Matrix3d d_res;  // d residual / d point_in_cam; row 2 only used for RGB-D.
    const double inv_z2 = inv_z * inv_z;
    d_res << camera_.fx * inv_z, 0.0, -camera_.fx * p.x() * inv_z2,  //
        0.0, camera_.fy * inv_z, -camera_.fy * p.y() * inv_z2,        //
        camera_.fx * inv_z, 0.0, -camera_.fx * p.x() * inv_z2 + bf_ * inv_z2;
    d_res *= -sqrt_info_;

    if (jacobians[0] != nullptr) {
      Eigen::Matrix3d skew;
      skew << 0.0, -point_in_world.z(), point_in_world.y(), point_in_world.z(), 0.0, -point_in_world.x(),
          -point_in_world.y(), point_in_world.x(), 0.0;
      const Eigen::Matrix3d d_rot = d_res * (-r * skew);
      for (int row = 0; row < n; ++row) {
        double* j = jacobians[0] + row * kPoseBlockSize;
        for (int c = 0; c < 3; ++c) {
          j[c] = d_res(row, c);
          j[3 + c] = d_rot(row, c);
        }
        j[6] = 0.0;
      }
    }
    if (!has_fixed_point_ && jacobians[1] != nullptr) {
      const Eigen::Matrix3d d_point = d_res * r;
      for (int row = 0; row < n; ++row) {
        for (int c = 0; c < 3; ++c) jacobians[1][row * 3 + c] = d_point(row, c);
      }
    }
    return true;
  }

 private:
  PinholeCamera camera_;
  double bf_;
  KeypointObservation obs_;
  double sqrt_info_;
  bool has_fixed_point_;
  Eigen::Vector3d fixed_point_ = Eigen::Vector3d::Zero();
};

}  // namespace

ceres::CostFunction* NewReprojectionCost(const PinholeCamera& camera, double bf, const KeypointObservation& obs) {
  return new ReprojectionCost(camera, bf, obs, nullptr);
}

ceres::CostFunction* NewPoseOnlyReprojectionCost(const PinholeCamera& camera, double bf,
                                                 const KeypointObservation& obs,
                                                 const Eigen::Vector3d& point_in_world) {
  return new ReprojectionCost(camera, bf, obs, &point_in_world);
}

double ReprojectionChi2(const PinholeCamera& camera, double bf, const KeypointObservation& obs,
                        const Eigen::Vector3d& point_in_cam) {
  if (point_in_cam.z() <= kMinDepth) return std::numeric_limits<double>::infinity();
  const double inv_z = 1.0 / point_in_cam.z();
  const double u = camera.fx * point_in_cam.x() * inv_z + camera.cx;
  const double v = camera.fy * point_in_cam.y() * inv_z + camera.cy;
  double e2 = (obs.uv.x() - u) * (obs.uv.x() - u) + (obs.uv.y() - v) * (obs.uv.y() - v);
  if (obs.IsStereo()) {
    const double ur = u - bf * inv_z;
    e2 += (obs.u_right - ur) * (obs.u_right - ur);
  }
  return obs.information * e2;
}

}  // namespace dynorb
