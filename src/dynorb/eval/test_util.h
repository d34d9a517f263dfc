// Helpers shared by the eval tests (not part of the library).
#pragma once

#include <Eigen/Geometry>
#include <cmath>

#include "dynorb/core/trajectory.h"

namespace dynorb::testing_util {

// A smooth rotating, moving trajectory with `n` poses at `rate_hz` starting at t0.
inline Trajectory Wiggle(int n, double rate_hz, double t0 = 100.0) {
  Trajectory traj(n);
  for (int k = 0; k < n; ++k) {
    const double t = k / rate_hz;
    traj[k].timestamp_s = t0 + t;
    const Eigen::Quaterniond q(
        Eigen::AngleAxisd(0.5 * std::sin(0.7 * t), Eigen::Vector3d::UnitZ()) *
        Eigen::AngleAxisd(0.2 * std::cos(0.4 * t), Eigen::Vector3d::UnitX()));
    traj[k].world_from_cam = Rigid3d(
        q, Eigen::Vector3d(std::sin(0.3 * t), 0.5 * std::cos(0.5 * t), 0.2 * std::sin(0.9 * t)));
  }
  return traj;
}

// Applies `b_from_a` to every pose of a trajectory given in frame a.
inline Trajectory Transformed(const Trajectory& traj, const Rigid3d& b_from_a) {
  Trajectory out = traj;
  for (StampedPose& p : out) p.world_from_cam = b_from_a * p.world_from_cam;
  return out;
}

}  // namespace dynorb::testing_util
