#include "dynorb/optimization/bundle_adjuster.h"

#include <random>

#include <gtest/gtest.h>

#include "dynorb/optimization/test_scene.h"

namespace dynorb {
namespace {

const PinholeCamera kCamera = TumFreiburg3Camera();
constexpr double kBf = 40.0;

TEST(BundleAdjuster, ReducesPerturbationOfPosesAndPoints) {
  std::mt19937_64 rng(31);
  // Five keyframes along a short arc, all looking at a cloud of points.
  std::vector<Rigid3d> truth;
  for (int k = 0; k < 5; ++k) {
    const Rigid3d world_from_cam(Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * k, Eigen::Vector3d::UnitY())),
                                 Eigen::Vector3d(0.15 * k, 0.02 * k, 0.0));
    truth.push_back(world_from_cam.Inverse());
  }
  const std::vector<Eigen::Vector3d> points = testing::RandomPointsInWorld(400, rng);
  std::vector<BaObservation> observations;
  int outliers = 0;
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (size_t k = 0; k < truth.size(); ++k) {
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d p = truth[k] * points[i];
      if (p.z() < 0.5 || !kCamera.InImage(kCamera.Project(p))) continue;
      BaObservation obs;
      obs.keyframe_index = k;
      obs.landmark_index = i;
      obs.keypoint = testing::Observe(kCamera, kBf, truth[k], points[i], i % 2 == 0, 0.5, rng);
      if (u01(rng) < 0.05) {
        obs.keypoint.uv += Eigen::Vector2d(25.0, -30.0);
        ++outliers;
      }
      observations.push_back(obs);
    }
  }
  std::vector<BaKeyframe> keyframes;
  for (size_t k = 0; k < truth.size(); ++k) {
    BaKeyframe kf;
    kf.fixed = k < 2;  // Two fixed keyframes anchor the gauge.
    kf.cam_from_world = kf.fixed ? truth[k] : testing::Perturb(truth[k], 0.01, 0.03, rng);
    keyframes.push_back(kf);
  }
  std::vector<Eigen::Vector3d> noisy_points = points;
  std::normal_distribution<double> n(0.0, 0.15);  // Well above what the measurements resolve.
  for (Eigen::Vector3d& p : noisy_points) p += Eigen::Vector3d(n(rng), n(rng), n(rng));

  const BundleAdjusterResult r = RunBundleAdjustment(kCamera, kBf, keyframes, noisy_points, observations);
  ASSERT_TRUE(r.converged);
  EXPECT_LT(r.final_cost, 0.05 * r.initial_cost);
  for (size_t k = 0; k < truth.size(); ++k) {
    const Rigid3d err = r.cam_from_world[k] * truth[k].Inverse();
    if (keyframes[k].fixed) {
      EXPECT_EQ(r.cam_from_world[k].translation, truth[k].translation);
    } else {
      EXPECT_LT(err.translation.norm(), 0.003) << "keyframe " << k;
      EXPECT_LT(RotationAngleRad(err.rotation), 0.1 * M_PI / 180.0) << "keyframe " << k;
    }
  }
  // Points constrained by depth (an RGB-D observation) or by >= 3 views must converge; a point
  // seen once without depth is free along its ray and is not checked.
  std::vector<int> views(points.size(), 0);
  std::vector<bool> has_depth(points.size(), false);
  for (const BaObservation& obs : observations) {
    ++views[obs.landmark_index];
    has_depth[obs.landmark_index] = has_depth[obs.landmark_index] || obs.keypoint.IsStereo();
  }
  double point_error = 0.0, noisy_error = 0.0;
  int checked = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!has_depth[i] && views[i] < 3) continue;
    point_error += (r.points_in_world[i] - points[i]).norm();
    noisy_error += (noisy_points[i] - points[i]).norm();
    ++checked;
  }
  ASSERT_GT(checked, 100);
  EXPECT_LT(point_error / checked, 0.4 * noisy_error / checked);
  int flagged = 0;
  for (bool inlier : r.observation_inlier) flagged += inlier ? 0 : 1;
  EXPECT_GE(flagged, outliers);
  EXPECT_LT(flagged, outliers + 0.1 * observations.size());
}

}  // namespace
}  // namespace dynorb
