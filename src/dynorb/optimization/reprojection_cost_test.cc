#include "dynorb/optimization/reprojection_cost.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include "dynorb/optimization/pose_block.h"
#include "dynorb/optimization/test_scene.h"

namespace dynorb {
namespace {

const PinholeCamera kCamera = TumFreiburg3Camera();
constexpr double kBf = 40.0;

TEST(PoseManifold, PlusMinusRoundTrip) {
  std::unique_ptr<ceres::Manifold> manifold(NewPoseManifold());
  std::mt19937_64 rng(3);
  const Rigid3d pose = testing::Perturb(Rigid3d(), 0.7, 1.0, rng);
  const PoseBlock x = ToPoseBlock(pose);
  const double delta[6] = {0.1, -0.2, 0.05, 0.02, -0.3, 0.1};
  PoseBlock y;
  ASSERT_TRUE(manifold->Plus(x.data(), delta, y.data()));
  double back[6];
  ASSERT_TRUE(manifold->Minus(y.data(), x.data(), back));
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(back[i], delta[i], 1e-12);
  // Plus applies the rotation on the right: R_new = R * Exp(dtheta).
  const Rigid3d py = FromPoseBlock(y.data());
  const Eigen::Quaterniond expected =
      pose.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(Eigen::Vector3d(0.02, -0.3, 0.1).norm(),
                                                           Eigen::Vector3d(0.02, -0.3, 0.1).normalized()));
  EXPECT_LT(py.rotation.angularDistance(expected), 1e-12);
}

// Central differences of the residual through the manifold's Plus (tangent-space Jacobian),
// compared with the analytic Jacobian restricted to the tangent (the first 6 pose columns).
// (ceres::GradientChecker differentiates in the ambient quaternion space, which does not apply to
// the tangent-column convention documented in pose_block.h.)
void CheckJacobians(bool stereo, bool pose_only, double disparity_sigma_px = 0.0) {
  std::mt19937_64 rng(stereo ? 11 : 12);
  const Rigid3d cam_from_world = testing::Perturb(Rigid3d(), 0.3, 0.5, rng);
  const Eigen::Vector3d point_in_world = cam_from_world.Inverse() * Eigen::Vector3d(0.4, -0.3, 2.5);
  KeypointObservation obs = testing::Observe(kCamera, kBf, cam_from_world, point_in_world, stereo, 2.0, rng);
  obs.information = 1.0 / 1.44;
  if (disparity_sigma_px > 0.0)
    obs.disparity_information = 1.0 / (disparity_sigma_px * disparity_sigma_px);
  std::unique_ptr<ceres::CostFunction> cost(
      pose_only ? NewPoseOnlyReprojectionCost(kCamera, kBf, obs, point_in_world)
                : NewReprojectionCost(kCamera, kBf, obs));
  std::unique_ptr<ceres::Manifold> manifold(NewPoseManifold());
  const int n = stereo ? 3 : 2;
  ASSERT_EQ(cost->num_residuals(), n);
  const PoseBlock pose = ToPoseBlock(cam_from_world);
  Eigen::Vector3d point = point_in_world;

  double j_pose[3 * kPoseBlockSize], j_point[9], residuals[3];
  double* jacobians[2] = {j_pose, j_point};
  const double* params[2] = {pose.data(), point.data()};
  ASSERT_TRUE(cost->Evaluate(params, residuals, jacobians));

  auto evaluate = [&](const PoseBlock& p, const Eigen::Vector3d& x) {
    const double* ps[2] = {p.data(), x.data()};
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    EXPECT_TRUE(cost->Evaluate(ps, r.data(), nullptr));
    return r;
  };
  const double h = 1e-6;
  for (int c = 0; c < kPoseTangentSize; ++c) {
    double delta[6] = {0, 0, 0, 0, 0, 0};
    PoseBlock plus, minus;
    delta[c] = h;
    manifold->Plus(pose.data(), delta, plus.data());
    delta[c] = -h;
    manifold->Plus(pose.data(), delta, minus.data());
    const Eigen::Vector3d numeric = (evaluate(plus, point) - evaluate(minus, point)) / (2 * h);
    for (int r = 0; r < n; ++r) {
      EXPECT_NEAR(j_pose[r * kPoseBlockSize + c], numeric[r], 1e-5 * (1.0 + std::abs(numeric[r])))
          << "pose row " << r << " col " << c;
    }
  }
  for (int r = 0; r < n; ++r) EXPECT_EQ(j_pose[r * kPoseBlockSize + 6], 0.0);
  if (pose_only) return;
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d plus = point, minus = point;
    plus[c] += h;
    minus[c] -= h;
    const Eigen::Vector3d numeric = (evaluate(pose, plus) - evaluate(pose, minus)) / (2 * h);
    for (int r = 0; r < n; ++r) {
      EXPECT_NEAR(j_point[r * 3 + c], numeric[r], 1e-5 * (1.0 + std::abs(numeric[r])))
          << "point row " << r << " col " << c;
    }
  }
}

TEST(ReprojectionCost, MonoJacobians) { CheckJacobians(false, false); }
TEST(ReprojectionCost, StereoJacobians) { CheckJacobians(true, false); }
TEST(ReprojectionCost, PoseOnlyMonoJacobians) { CheckJacobians(false, true); }
TEST(ReprojectionCost, PoseOnlyStereoJacobians) { CheckJacobians(true, true); }
TEST(ReprojectionCost, DisparityJacobians) { CheckJacobians(true, false, 0.15); }
TEST(ReprojectionCost, PoseOnlyDisparityJacobians) { CheckJacobians(true, true, 0.15); }

// The batch cost is the per-observation pose-only costs stacked: same residuals and Jacobian rows
// for a mix of monocular and RGB-D observations with different weights.
TEST(ReprojectionCost, PoseOnlyBatchStacksThePerObservationCosts) {
  std::mt19937_64 rng(21);
  const Rigid3d cam_from_world = testing::Perturb(Rigid3d(), 0.2, 0.3, rng);
  const std::vector<Eigen::Vector3d> points = testing::RandomPointsInWorld(7, rng);
  std::vector<KeypointObservation> observations;
  for (size_t i = 0; i < points.size(); ++i) {
    observations.push_back(
        testing::Observe(kCamera, kBf, cam_from_world, points[i], i % 3 == 0, 1.5, rng));
    observations.back().information = 1.0 / (1.0 + 0.2 * i);
    if (i % 2 == 0) observations.back().disparity_information = 1.0 / (0.1 + 0.05 * i);
  }
  std::unique_ptr<ceres::CostFunction> batch(
      NewPoseOnlyBatchCost(kCamera, kBf, observations, points));
  const PoseBlock pose = ToPoseBlock(testing::Perturb(cam_from_world, 0.01, 0.02, rng));
  const int rows = batch->num_residuals();
  ASSERT_EQ(rows, 3 * 3 + 4 * 2);
  std::vector<double> residuals(rows), jacobian(rows * kPoseBlockSize);
  double* batch_jacobians[1] = {jacobian.data()};
  const double* params[1] = {pose.data()};
  ASSERT_TRUE(batch->Evaluate(params, residuals.data(), batch_jacobians));
  int row = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    std::unique_ptr<ceres::CostFunction> one(
        NewPoseOnlyReprojectionCost(kCamera, kBf, observations[i], points[i]));
    double r[3], j[3 * kPoseBlockSize];
    double* one_jacobians[1] = {j};
    ASSERT_TRUE(one->Evaluate(params, r, one_jacobians));
    for (int k = 0; k < one->num_residuals(); ++k, ++row) {
      EXPECT_DOUBLE_EQ(residuals[row], r[k]) << "observation " << i;
      for (int c = 0; c < kPoseBlockSize; ++c) {
        EXPECT_DOUBLE_EQ(jacobian[row * kPoseBlockSize + c], j[k * kPoseBlockSize + c]);
      }
    }
  }
  EXPECT_EQ(row, rows);
  // Residuals only (Ceres' cost evaluations): no Jacobians at all, or a null pose Jacobian.
  std::vector<double> again(rows);
  ASSERT_TRUE(batch->Evaluate(params, again.data(), nullptr));
  EXPECT_EQ(again, residuals);
  double* no_pose_jacobian[1] = {nullptr};
  std::fill(again.begin(), again.end(), 0.0);
  ASSERT_TRUE(batch->Evaluate(params, again.data(), no_pose_jacobian));
  EXPECT_EQ(again, residuals);
  EXPECT_DEATH(NewPoseOnlyBatchCost(kCamera, kBf, observations, {points[0]}),
               "one point per observation");
}

TEST(ReprojectionCost, ZeroResidualAtTruthAndChi2) {
  std::mt19937_64 rng(5);
  const Rigid3d cam_from_world = testing::Perturb(Rigid3d(), 0.2, 0.3, rng);
  const Eigen::Vector3d point_in_world = cam_from_world.Inverse() * Eigen::Vector3d(-0.5, 0.2, 3.0);
  KeypointObservation obs = testing::Observe(kCamera, kBf, cam_from_world, point_in_world, true, 0.0, rng);
  std::unique_ptr<ceres::CostFunction> cost(NewReprojectionCost(kCamera, kBf, obs));
  PoseBlock pose = ToPoseBlock(cam_from_world);
  const double* params[2] = {pose.data(), point_in_world.data()};
  double residuals[3];
  ASSERT_TRUE(cost->Evaluate(params, residuals, nullptr));
  for (double r : residuals) EXPECT_NEAR(r, 0.0, 1e-9);
  EXPECT_NEAR(ReprojectionChi2(kCamera, kBf, obs, cam_from_world * point_in_world), 0.0, 1e-12);
  obs.uv.x() += 2.0;
  obs.information = 0.25;
  EXPECT_NEAR(ReprojectionChi2(kCamera, kBf, obs, cam_from_world * point_in_world), 1.0, 1e-9);
  EXPECT_TRUE(std::isinf(ReprojectionChi2(kCamera, kBf, obs, Eigen::Vector3d(0, 0, -1))));
}

// With a disparity information the third residual is the disparity d = u - u_r against bf / z,
// weighted by the depth's own sigma: a pixel error in u alone leaves it at zero (ORB-SLAM2's u_r
// residual would count it twice), a depth error shows in it alone, and ReprojectionChi2 is the
// squared norm of the residuals.
TEST(ReprojectionCost, DisparityResidualWeighsTheDepthByItsOwnSigma) {
  std::mt19937_64 rng(6);
  const Rigid3d cam_from_world = testing::Perturb(Rigid3d(), 0.2, 0.3, rng);
  const Eigen::Vector3d p_cam(-0.5, 0.2, 2.0);
  const Eigen::Vector3d point_in_world = cam_from_world.Inverse() * p_cam;
  KeypointObservation obs =
      testing::Observe(kCamera, kBf, cam_from_world, point_in_world, true, 0.0, rng);
  obs.information = 0.25;                  // 2-px keypoint sigma.
  obs.disparity_information = 1.0 / 0.01;  // 0.1-px disparity sigma.
  std::unique_ptr<ceres::CostFunction> cost(NewReprojectionCost(kCamera, kBf, obs));
  const PoseBlock pose = ToPoseBlock(cam_from_world);
  const double* params[2] = {pose.data(), point_in_world.data()};
  auto residuals_of = [&](const KeypointObservation& o) {
    std::unique_ptr<ceres::CostFunction> c(NewReprojectionCost(kCamera, kBf, o));
    Eigen::Vector3d r;
    EXPECT_TRUE(c->Evaluate(params, r.data(), nullptr));
    return r;
  };
  EXPECT_LT(residuals_of(obs).norm(), 1e-9);
  // The keypoint 1 px right, same depth: u and u_r move together, the disparity does not.
  KeypointObservation shifted = obs;
  shifted.uv.x() += 1.0;
  shifted.u_right += 1.0;
  Eigen::Vector3d r = residuals_of(shifted);
  EXPECT_NEAR(r[0], 0.5, 1e-9);
  EXPECT_NEAR(r[2], 0.0, 1e-9);
  EXPECT_NEAR(ReprojectionChi2(kCamera, kBf, shifted, p_cam), r.squaredNorm(), 1e-9);
  shifted.disparity_information = 0.0;  // ORB-SLAM2's form: the u_r residual sees the same pixel.
  EXPECT_NEAR(residuals_of(shifted)[2], 0.5, 1e-9);
  // The depth 1 % farther: the disparity bf / z = 20 px drops by 0.198 px, ~2 sigma of 0.1 px.
  KeypointObservation farther = obs;
  farther.u_right = obs.uv.x() - kBf / (1.01 * p_cam.z());
  r = residuals_of(farther);
  EXPECT_NEAR(r[0], 0.0, 1e-9);
  EXPECT_NEAR(r[2], (kBf / (1.01 * p_cam.z()) - kBf / p_cam.z()) / 0.1, 1e-9);
  EXPECT_NEAR(r[2], -1.98, 0.01);
  EXPECT_NEAR(ReprojectionChi2(kCamera, kBf, farther, p_cam), r.squaredNorm(), 1e-9);
}

}  // namespace
}  // namespace dynorb
