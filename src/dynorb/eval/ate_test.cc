#include "dynorb/eval/ate.h"

#include <gtest/gtest.h>

#include <cmath>

#include "dynorb/core/error.h"
#include "dynorb/eval/evaluate.h"
#include "dynorb/eval/test_util.h"

namespace dynorb {
namespace {

using testing_util::Transformed;
using testing_util::Wiggle;

EvalOptions Opts(AlignmentMode mode) {
  EvalOptions o;
  o.alignment = mode;
  return o;
}

TEST(Ate, PureOffsetIsZeroAfterSe3AndKnownWithoutAlignment) {
  const Trajectory gt = Wiggle(300, 30.0);
  const Eigen::Vector3d offset(0.3, -0.4, 0.0);  // |offset| = 0.5 m
  const Trajectory est = Transformed(gt, Rigid3d(Eigen::Quaterniond::Identity(), offset));
  const EvalResult se3 = EvaluateTrajectories(gt, est, Opts(AlignmentMode::kSe3));
  EXPECT_EQ(se3.ate.stats.count, 300);
  EXPECT_LT(se3.ate.stats.rmse, 1e-12);
  EXPECT_LT((se3.ate.gt_from_est.translation + offset).norm(), 1e-12);
  const EvalResult none = EvaluateTrajectories(gt, est, Opts(AlignmentMode::kNone));
  EXPECT_NEAR(none.ate.stats.rmse, 0.5, 1e-12);
  EXPECT_NEAR(none.ate.stats.mean, 0.5, 1e-12);
  EXPECT_NEAR(none.ate.stats.max, 0.5, 1e-12);
  EXPECT_NEAR(none.ate.stats.stddev, 0.0, 1e-12);
}

TEST(Ate, KnownRotationIsRemovedBySe3) {
  const Trajectory gt = Wiggle(200, 30.0);
  const Rigid3d est_from_gt(
      Eigen::Quaterniond(Eigen::AngleAxisd(1.2, Eigen::Vector3d(0.2, 1, 0.3).normalized())),
      Eigen::Vector3d(5, -2, 1));
  const EvalResult r =
      EvaluateTrajectories(gt, Transformed(gt, est_from_gt), Opts(AlignmentMode::kSe3));
  EXPECT_LT(r.ate.stats.max, 1e-10);
  const Eigen::Matrix3d expected = est_from_gt.Inverse().rotation.toRotationMatrix();
  EXPECT_LT((r.ate.gt_from_est.rotation - expected).norm(), 1e-10);
  // Without alignment the error of each pose is |p - (R p + t)|.
  const EvalResult none =
      EvaluateTrajectories(gt, Transformed(gt, est_from_gt), Opts(AlignmentMode::kNone));
  const Eigen::Vector3d p0 = gt[0].world_from_cam.translation;
  EXPECT_NEAR(none.ate.errors_m[0], (p0 - est_from_gt * p0).norm(), 1e-12);
}

TEST(Ate, SymmetricNoiseGivesExactRmseAfterSe3) {
  // Every position is visited twice and perturbed by +e and -e: the noise has zero mean and zero
  // correlation with the positions, so the optimal alignment is the identity and every error is
  // |e|.
  const Trajectory base = Wiggle(100, 10.0);
  Trajectory gt, est;
  const double d[4] = {0.01, 0.02, 0.03, 0.04};
  for (size_t k = 0; k < base.size(); ++k) {
    const Eigen::Vector3d e = d[k % 4] * Eigen::Vector3d(std::cos(k * 1.0), std::sin(k * 1.0), 0.0);
    for (int sign : {1, -1}) {
      StampedPose g = base[k];
      g.timestamp_s = 100.0 + 0.05 * static_cast<double>(gt.size());
      StampedPose e_pose = g;
      e_pose.world_from_cam.translation += sign * e;
      gt.push_back(g);
      est.push_back(e_pose);
    }
  }
  const EvalResult r = EvaluateTrajectories(gt, est, Opts(AlignmentMode::kSe3));
  const double expected_rmse = std::sqrt((1e-4 + 4e-4 + 9e-4 + 16e-4) / 4.0);
  EXPECT_NEAR(r.ate.stats.rmse, expected_rmse, 1e-12);
  EXPECT_NEAR(r.ate.stats.mean, 0.025, 1e-12);
  EXPECT_NEAR(r.ate.stats.median, 0.025, 1e-12);  // numpy.median: mean of the two middle values
  EXPECT_NEAR(r.ate.stats.stddev, std::sqrt(1.25e-4), 1e-12);  // population std
  EXPECT_NEAR(r.ate.stats.min, 0.01, 1e-12);
  EXPECT_NEAR(r.ate.stats.max, 0.04, 1e-12);
  EXPECT_LT((r.ate.gt_from_est.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(Ate, Sim3RecoversScale) {
  const Trajectory gt = Wiggle(300, 30.0);
  Trajectory est = gt;
  const Rigid3d frame(Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY())),
                      Eigen::Vector3d(1, 2, 3));
  for (StampedPose& p : est) {
    p.world_from_cam.translation *= 0.4;  // monocular: unknown scale
    p.world_from_cam = frame * p.world_from_cam;
  }
  const EvalResult sim3 = EvaluateTrajectories(gt, est, Opts(AlignmentMode::kSim3));
  EXPECT_NEAR(sim3.ate.gt_from_est.scale, 2.5, 1e-10);
  EXPECT_LT(sim3.ate.stats.rmse, 1e-10);
  const EvalResult se3 = EvaluateTrajectories(gt, est, Opts(AlignmentMode::kSe3));
  EXPECT_GT(se3.ate.stats.rmse, 0.05);
  // RPE uses the recovered scale: a scaled but otherwise exact estimate has zero RPE.
  EXPECT_LT(sim3.rpe.trans_m.max, 1e-9);
  EXPECT_GT(se3.rpe.trans_m.max, 0.01);
}

TEST(Ate, OnlyAssociatedPosesCount) {
  const Trajectory gt = Wiggle(100, 10.0);
  Trajectory est = gt;
  for (StampedPose& p : est) p.timestamp_s += 0.005;  // within max_diff 0.02
  StampedPose far = est.back();
  far.timestamp_s += 5.0;
  far.world_from_cam.translation += Eigen::Vector3d(100, 0, 0);  // no ground truth: ignored
  est.push_back(far);
  const EvalResult r = EvaluateTrajectories(gt, est, Opts(AlignmentMode::kSe3));
  EXPECT_EQ(r.ate.stats.count, 100);
  EXPECT_LT(r.ate.stats.rmse, 1e-12);
}

TEST(Ate, ClearErrorsForNoOverlapAndTooFewPairs) {
  const Trajectory gt = Wiggle(100, 10.0);
  Trajectory late = gt;
  for (StampedPose& p : late) p.timestamp_s += 1000.0;
  try {
    EvaluateTrajectories(gt, late, Opts(AlignmentMode::kSe3));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no estimate pose has a ground-truth pose"),
              std::string::npos);
  }
  const Trajectory two(gt.begin(), gt.begin() + 2);
  EXPECT_THROW(EvaluateTrajectories(gt, two, Opts(AlignmentMode::kSe3)), InputError);
  EXPECT_NO_THROW(EvaluateTrajectories(gt, two, Opts(AlignmentMode::kNone)));
  EXPECT_THROW(ComputeAte(gt, gt, {}, AlignmentMode::kNone), InputError);
}

}  // namespace
}  // namespace dynorb
