// Exact synthetic scenes for the optimisation tests: random points in front of a camera and
// their exact projections (with optional noise and outliers). Test-only helper.
#pragma once

#include <random>
#include <vector>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/optimization/reprojection_cost.h"

namespace dynorb::testing {

inline std::vector<Eigen::Vector3d> RandomPointsInWorld(int count, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> xy(-2.0, 2.0), z(1.0, 5.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) points.emplace_back(xy(rng), xy(rng) * 0.75, z(rng));
  return points;
}

// Projects with pixel noise sigma (0: exact, no random draws); u_right from the true depth
// (RGB-D) when `stereo`.
inline KeypointObservation Observe(const PinholeCamera& cam, double bf, const Rigid3d& cam_from_world,
                                   const Eigen::Vector3d& point_in_world, bool stereo, double sigma_px,
                                   std::mt19937_64& rng) {
  std::normal_distribution<double> unit(0.0, 1.0);
  auto noise = [&]() { return sigma_px > 0.0 ? sigma_px * unit(rng) : 0.0; };
  const Eigen::Vector3d p = cam_from_world * point_in_world;
  KeypointObservation obs;
  const Eigen::Vector2d uv = cam.Project(p);
  obs.uv = uv + Eigen::Vector2d(noise(), noise());
  // Independent noise on u_r (as from an independent depth error).
  if (stereo) obs.u_right = uv.x() - bf / p.z() + noise();
  obs.information = 1.0;
  return obs;
}

inline Rigid3d Perturb(const Rigid3d& pose, double angle_rad, double translation_m, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
  const Eigen::Vector3d dir = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis)) * pose.rotation,
                 pose.translation + translation_m * dir);
}

}  // namespace dynorb::testing
