#include "dynorb/geometry/two_view.h"

#include <gtest/gtest.h>

namespace dynorb {
namespace {

const PinholeCamera kCamera = TumFreiburg3Camera();

Rigid3d Pose(double yaw, const Eigen::Vector3d& world_position) {
  const Rigid3d world_from_cam(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY())), world_position);
  return world_from_cam.Inverse();
}

Eigen::Vector2d Normalized(const Rigid3d& cam_from_world, const Eigen::Vector3d& p) {
  const Eigen::Vector3d c = cam_from_world * p;
  return c.head<2>() / c.z();
}

TEST(TriangulateDlt, RecoversExactPoint) {
  const Rigid3d c1 = Pose(0.0, {0, 0, 0});
  const Rigid3d c2 = Pose(0.1, {0.3, 0.05, 0.1});
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.2, -0.1, 2.0), Eigen::Vector3d(-1.0, 0.4, 4.5)}) {
    const auto x = TriangulateDlt(c1, Normalized(c1, p), c2, Normalized(c2, p));
    ASSERT_TRUE(x.has_value());
    EXPECT_LT((*x - p).norm(), 1e-9);
  }
}

TEST(FundamentalFromPoses, EpipolarConstraintHolds) {
  const Rigid3d c1 = Pose(0.05, {0, 0, 0});
  const Rigid3d c2 = Pose(-0.1, {0.25, -0.05, 0.2});
  const Eigen::Matrix3d f21 = FundamentalFromPoses(kCamera, c1, c2);
  const Eigen::Vector3d p(0.3, 0.2, 3.0);
  const Eigen::Vector2d x1 = kCamera.Project(c1 * p), x2 = kCamera.Project(c2 * p);
  EXPECT_LT(EpipolarDistancePx(f21, x1, x2), 1e-9);
  EXPECT_NEAR(EpipolarDistancePx(f21, x1, x2 + Eigen::Vector2d(0, 0)), 0.0, 1e-9);
  // A point shifted off the line by d pixels along the line normal is at distance d.
  const Eigen::Vector3d line = f21 * x1.homogeneous();
  const Eigen::Vector2d normal = line.head<2>().normalized();
  EXPECT_NEAR(EpipolarDistancePx(f21, x1, x2 + 2.5 * normal), 2.5, 1e-9);
}

}  // namespace
}  // namespace dynorb
