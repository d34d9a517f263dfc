// Two-view geometry of calibrated, posed cameras.
//
// TriangulateDlt: the linear (DLT) triangulation of Hartley & Zisserman §12.2 — the point X that
// minimises the algebraic error of x1 ~ P1 X and x2 ~ P2 X, via the SVD of the 4x4 system,
// with xi in normalised camera coordinates (K^-1 applied) and Pi = [R | t] = cam_i_from_world.
// FundamentalFromPoses: F21 with  x2^T F21 x1 = 0  for pixels x1 in camera 1 and x2 in camera 2,
// F21 = K^-T [t21]_x R21 K^-1, where cam2_from_cam1 = [R21 | t21].
// Pure functions; thread-safe.
#pragma once

#include <optional>

#include <Eigen/Core>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"

namespace dynorb {

// Returns nothing when the system is degenerate (the homogeneous coordinate vanishes).
std::optional<Eigen::Vector3d> TriangulateDlt(const Rigid3d& cam1_from_world, const Eigen::Vector2d& normalized1,
                                              const Rigid3d& cam2_from_world, const Eigen::Vector2d& normalized2);

Eigen::Matrix3d FundamentalFromPoses(const PinholeCamera& camera, const Rigid3d& cam1_from_world,
                                     const Rigid3d& cam2_from_world);
// The same from the relative motion cam2_from_cam1 directly.
Eigen::Matrix3d FundamentalFromMotion(const PinholeCamera& camera, const Rigid3d& cam2_from_cam1);

// Distance in pixels of pixel x2 (camera 2) to the epipolar line F21 * x1.
double EpipolarDistancePx(const Eigen::Matrix3d& f21, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2);

}  // namespace dynorb
