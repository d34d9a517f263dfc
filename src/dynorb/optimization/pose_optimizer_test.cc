#include "dynorb/optimization/pose_optimizer.h"

#include <random>

#include <gtest/gtest.h>

#include "dynorb/core/error.h"
#include "dynorb/optimization/test_scene.h"

namespace dynorb {
namespace {

const PinholeCamera kCamera = TumFreiburg3Camera();
constexpr double kBf = 40.0;

struct Scenario {
  Rigid3d truth;
  std::vector<PoseObservation> observations;
  std::vector<bool> is_outlier;
};

Scenario MakeScenario(int count, double outlier_fraction, bool stereo, std::mt19937_64& rng) {
  Scenario s;
  s.truth = testing::Perturb(Rigid3d(), 0.2, 0.3, rng);
  const std::vector<Eigen::Vector3d> points_in_cam = testing::RandomPointsInWorld(count, rng);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (const Eigen::Vector3d& p_cam : points_in_cam) {
    PoseObservation obs;
    obs.point_in_world = s.truth.Inverse() * p_cam;
    obs.keypoint = testing::Observe(kCamera, kBf, s.truth, obs.point_in_world, stereo, 1.0, rng);
    const bool outlier = u01(rng) < outlier_fraction;
    if (outlier) {  // A wrong match: a random pixel anywhere in the image.
      obs.keypoint.uv = Eigen::Vector2d(u01(rng) * 640.0, u01(rng) * 480.0);
      if (stereo) obs.keypoint.u_right = obs.keypoint.uv.x() - kBf / p_cam.z();
    }
    s.observations.push_back(obs);
    s.is_outlier.push_back(outlier);
  }
  return s;
}

void ExpectRecovers(bool stereo) {
  std::mt19937_64 rng(stereo ? 21 : 22);
  const Scenario s = MakeScenario(300, 0.2, stereo, rng);
  const Rigid3d initial = testing::Perturb(s.truth, 3.0 * M_PI / 180.0, 0.05, rng);
  const PoseOptimizerResult r = OptimizePose(kCamera, kBf, s.observations, initial);
  const Rigid3d error = r.cam_from_world * s.truth.Inverse();
  EXPECT_LT(error.translation.norm(), 0.005);
  EXPECT_LT(RotationAngleRad(error.rotation) * 180.0 / M_PI, 0.1);
  int outliers_found = 0, outliers = 0, inliers_kept = 0, inliers = 0;
  for (size_t i = 0; i < s.observations.size(); ++i) {
    if (s.is_outlier[i]) {
      ++outliers;
      outliers_found += r.inlier[i] ? 0 : 1;
    } else {
      ++inliers;
      inliers_kept += r.inlier[i] ? 1 : 0;
    }
  }
  EXPECT_GE(outliers_found, 0.95 * outliers);
  EXPECT_GE(inliers_kept, 0.9 * inliers);  // ~95 % of N(0,1) residuals pass a 95 % gate.
  EXPECT_EQ(r.num_inliers, static_cast<int>(std::count(r.inlier.begin(), r.inlier.end(), true)));
}

TEST(PoseOptimizer, RecoversKnownPoseMonoWithOutliers) { ExpectRecovers(false); }
TEST(PoseOptimizer, RecoversKnownPoseRgbdWithOutliers) { ExpectRecovers(true); }

TEST(PoseOptimizer, IsDeterministic) {
  std::mt19937_64 rng(7);
  const Scenario s = MakeScenario(150, 0.1, true, rng);
  const Rigid3d initial = testing::Perturb(s.truth, 0.02, 0.03, rng);
  const PoseOptimizerResult a = OptimizePose(kCamera, kBf, s.observations, initial);
  const PoseOptimizerResult b = OptimizePose(kCamera, kBf, s.observations, initial);
  EXPECT_EQ(a.cam_from_world.ToMatrix(), b.cam_from_world.ToMatrix());
  EXPECT_EQ(a.inlier, b.inlier);
}

TEST(PoseOptimizer, EmptyInputKeepsInitialPose) {
  const Rigid3d initial(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 2, 3));
  const PoseOptimizerResult r = OptimizePose(kCamera, kBf, {}, initial);
  EXPECT_EQ(r.cam_from_world.translation, initial.translation);
  EXPECT_EQ(r.num_inliers, 0);
}

TEST(PoseOptimizer, ValidateRejectsNonsense) {
  PoseOptimizerOptions options;
  options.num_rounds = 0;
  EXPECT_THROW(options.Validate(), InputError);
  EXPECT_NO_THROW(PoseOptimizerOptions().Validate());
}

}  // namespace
}  // namespace dynorb
