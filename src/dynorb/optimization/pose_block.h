// Pose parameter block shared by every Ceres problem in dynorb.
//
// A camera pose cam_from_world is stored as 7 doubles [tx, ty, tz, qx, qy, qz, qw]
// (translation, then an Eigen-ordered unit quaternion). Its tangent space has 6 dimensions
// [dt (3), dtheta (3)] with the update  t <- t + dt,  R <- R * Exp(dtheta)  (right perturbation
// of the rotation). Cost functions publish Jacobians for a 7-column ambient block whose first six
// columns hold the derivatives w.r.t. (dt, dtheta) and whose last column is zero; the manifold's
// PlusJacobian is [I6; 0], so Ceres' product J_ambient * PlusJacobian is the tangent Jacobian.
#pragma once

#include <array>

#include "dynorb/core/rigid3.h"

namespace ceres {
class Manifold;
}

namespace dynorb {

constexpr int kPoseBlockSize = 7;
constexpr int kPoseTangentSize = 6;
using PoseBlock = std::array<double, kPoseBlockSize>;

PoseBlock ToPoseBlock(const Rigid3d& cam_from_world);
Rigid3d FromPoseBlock(const double* block);

// A new manifold for pose blocks (caller or ceres::Problem takes ownership).
ceres::Manifold* NewPoseManifold();

}  // namespace dynorb
