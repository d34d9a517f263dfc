#include "dynorb/optimization/reprojection_cost.h"

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <ceres/cost_function.h>
#include <glog/logging.h>

#include "dynorb/optimization/pose_block.h"

namespace dynorb {
namespace {

constexpr double kMinDepth = 1e-6;

// Jacobians (d predicted / d point_in_cam), rows u, v, u_r:
//   [fx/z, 0, -fx x/z^2], [0, fy/z, -fy y/z^2], [fx/z, 0, -fx x/z^2 + bf/z^2];
// with a disparity information the third row is the disparity d = bf / z: [0, 0, -bf/z^2].
// d point_in_cam / d dt = I,  d point_in_cam / d dtheta = -R [point_in_world]_x  (R <- R
// Exp(dtheta)), d point_in_cam / d point_in_world = R. The residual is observed - predicted, hence
// the minus.
//
// Writes the 2 (mono) or 3 (RGB-D) residuals of one observation and, when not null, its rows of
// the pose Jacobian (kPoseBlockSize columns) and of the point Jacobian (3 columns).
// Fixed-size throughout: this runs for every residual at every iteration (no heap use).
void EvaluateObservation(const PinholeCamera& camera, double bf, const KeypointObservation& obs,
                         double sqrt_info, double sqrt_disparity_info, const Eigen::Matrix3d& r,
                         const Eigen::Vector3d& t, const Eigen::Vector3d& point_in_world,
                         double* residuals, double* jacobian_pose, double* jacobian_point) {
  const Eigen::Vector3d p = r * point_in_world + t;
  const double z = std::abs(p.z()) < kMinDepth ? (p.z() < 0 ? -kMinDepth : kMinDepth) : p.z();
  const double inv_z = 1.0 / z;
  const double u = camera.fx * p.x() * inv_z + camera.cx;
  const double v = camera.fy * p.y() * inv_z + camera.cy;
  const int n = obs.IsStereo() ? 3 : 2;
  residuals[0] = sqrt_info * (obs.uv.x() - u);
  residuals[1] = sqrt_info * (obs.uv.y() - v);
  const bool disparity = sqrt_disparity_info > 0.0;
  if (n == 3) {
    residuals[2] = disparity ? sqrt_disparity_info * ((obs.uv.x() - obs.u_right) - bf * inv_z)
                             : sqrt_info * (obs.u_right - (u - bf * inv_z));
  }
  if (jacobian_pose == nullptr && jacobian_point == nullptr) return;

  Eigen::Matrix3d d_res;  // d residual / d point_in_cam; row 2 only used for RGB-D.
  const double inv_z2 = inv_z * inv_z;
  d_res << camera.fx * inv_z, 0.0, -camera.fx * p.x() * inv_z2,  //
      0.0, camera.fy * inv_z, -camera.fy * p.y() * inv_z2,       //
      camera.fx * inv_z, 0.0, -camera.fx * p.x() * inv_z2 + bf * inv_z2;
  d_res *= -sqrt_info;
  if (disparity) d_res.row(2) = Eigen::RowVector3d(0.0, 0.0, sqrt_disparity_info * bf * inv_z2);

  if (jacobian_pose != nullptr) {
    Eigen::Matrix3d skew;
    skew << 0.0, -point_in_world.z(), point_in_world.y(), point_in_world.z(), 0.0,
        -point_in_world.x(), -point_in_world.y(), point_in_world.x(), 0.0;
    const Eigen::Matrix3d d_rot = d_res * (-r * skew);
    for (int row = 0; row < n; ++row) {
      double* j = jacobian_pose + row * kPoseBlockSize;
      for (int c = 0; c < 3; ++c) {
        j[c] = d_res(row, c);
        j[3 + c] = d_rot(row, c);
      }
      j[6] = 0.0;
    }
  }
  if (jacobian_point != nullptr) {
    const Eigen::Matrix3d d_point = d_res * r;
    for (int row = 0; row < n; ++row) {
      for (int c = 0; c < 3; ++c) jacobian_point[row * 3 + c] = d_point(row, c);
    }
  }
}

Eigen::Matrix3d RotationOfBlock(const double* pose) {
  return Eigen::Quaterniond(pose[6], pose[3], pose[4], pose[5]).normalized().toRotationMatrix();
}

class ReprojectionCost : public ceres::CostFunction {
 public:
  ReprojectionCost(const PinholeCamera& camera, double bf, const KeypointObservation& obs,
                   const Eigen::Vector3d* fixed_point)
      : camera_(camera),
        bf_(bf),
        obs_(obs),
        sqrt_info_(std::sqrt(obs.information)),
        sqrt_disparity_info_(std::sqrt(obs.disparity_information)),
        has_fixed_point_(fixed_point != nullptr) {
    if (has_fixed_point_) fixed_point_ = *fixed_point;
    set_num_residuals(obs.IsStereo() ? 3 : 2);
    mutable_parameter_block_sizes()->push_back(kPoseBlockSize);
    if (!has_fixed_point_) mutable_parameter_block_sizes()->push_back(3);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* pose = parameters[0];
    const Eigen::Vector3d point_in_world =
        has_fixed_point_ ? fixed_point_ : Eigen::Vector3d(parameters[1][0], parameters[1][1], parameters[1][2]);
    double* jacobian_pose = jacobians != nullptr ? jacobians[0] : nullptr;
    double* jacobian_point = jacobians != nullptr && !has_fixed_point_ ? jacobians[1] : nullptr;
    EvaluateObservation(camera_, bf_, obs_, sqrt_info_, sqrt_disparity_info_, RotationOfBlock(pose),
                        Eigen::Vector3d(pose[0], pose[1], pose[2]), point_in_world, residuals,
                        jacobian_pose, jacobian_point);
    return true;
  }

 private:
  PinholeCamera camera_;
  double bf_;
  KeypointObservation obs_;
  double sqrt_info_;
  double sqrt_disparity_info_;
  bool has_fixed_point_;
  Eigen::Vector3d fixed_point_ = Eigen::Vector3d::Zero();
};

// Pose-only residuals of many observations stacked in one block (Ceres' per-block bookkeeping
// paid once: for small fits repeated many times).
class PoseOnlyBatchCost : public ceres::CostFunction {
 public:
  PoseOnlyBatchCost(const PinholeCamera& camera, double bf,
                    std::vector<KeypointObservation> observations,
                    std::vector<Eigen::Vector3d> points_in_world)
      : camera_(camera),
        bf_(bf),
        observations_(std::move(observations)),
        points_(std::move(points_in_world)) {
    int n = 0;
    for (const KeypointObservation& obs : observations_) {
      sqrt_info_.push_back(std::sqrt(obs.information));
      sqrt_disparity_info_.push_back(std::sqrt(obs.disparity_information));
      n += obs.IsStereo() ? 3 : 2;
    }
    set_num_residuals(n);
    mutable_parameter_block_sizes()->push_back(kPoseBlockSize);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* pose = parameters[0];
    const Eigen::Matrix3d r = RotationOfBlock(pose);
    const Eigen::Vector3d t(pose[0], pose[1], pose[2]);
    double* jacobian = jacobians != nullptr ? jacobians[0] : nullptr;
    int row = 0;
    for (size_t i = 0; i < observations_.size(); ++i) {
      EvaluateObservation(camera_, bf_, observations_[i], sqrt_info_[i], sqrt_disparity_info_[i], r,
                          t, points_[i], residuals + row,
                          jacobian != nullptr ? jacobian + row * kPoseBlockSize : nullptr, nullptr);
      row += observations_[i].IsStereo() ? 3 : 2;
    }
    return true;
  }

 private:
  PinholeCamera camera_;
  double bf_;
  std::vector<KeypointObservation> observations_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<double> sqrt_info_;
  std::vector<double> sqrt_disparity_info_;
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

ceres::CostFunction* NewPoseOnlyBatchCost(const PinholeCamera& camera, double bf,
                                          std::vector<KeypointObservation> observations,
                                          std::vector<Eigen::Vector3d> points_in_world) {
  CHECK_EQ(observations.size(), points_in_world.size()) << "one point per observation";
  return new PoseOnlyBatchCost(camera, bf, std::move(observations), std::move(points_in_world));
}

double ReprojectionChi2(const PinholeCamera& camera, double bf, const KeypointObservation& obs,
                        const Eigen::Vector3d& point_in_cam) {
  if (point_in_cam.z() <= kMinDepth) return std::numeric_limits<double>::infinity();
  const double inv_z = 1.0 / point_in_cam.z();
  const double u = camera.fx * point_in_cam.x() * inv_z + camera.cx;
  const double v = camera.fy * point_in_cam.y() * inv_z + camera.cy;
  double e2 = (obs.uv.x() - u) * (obs.uv.x() - u) + (obs.uv.y() - v) * (obs.uv.y() - v);
  if (obs.IsStereo() && obs.disparity_information > 0.0) {
    const double dd = (obs.uv.x() - obs.u_right) - bf * inv_z;
    return obs.information * e2 + obs.disparity_information * dd * dd;
  }
  if (obs.IsStereo()) {
    const double ur = u - bf * inv_z;
    e2 += (obs.u_right - ur) * (obs.u_right - ur);
  }
  return obs.information * e2;
}

}  // namespace dynorb
