#include "dynorb/eval/rpe.h"

#include <gtest/gtest.h>

#include <cmath>

#include "dynorb/core/angles.h"
#include "dynorb/core/test_expect_error.h"
#include "dynorb/eval/association.h"
#include "dynorb/eval/test_util.h"

namespace dynorb {
namespace {

using testing_util::Transformed;
using testing_util::Wiggle;

TEST(Rpe, ZeroForRigidlyTransformedTrajectory) {
  const Trajectory gt = Wiggle(300, 30.0);
  const Trajectory est = Transformed(
      gt, Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 1, 0).normalized())),
                  Eigen::Vector3d(3, 4, 5)));
  const RpeResult r = ComputeRpe(gt, est, RpeOptions());
  ASSERT_GT(r.trans_m.count, 200);
  EXPECT_LT(r.trans_m.max, 1e-12);
  EXPECT_LT(r.rot_deg.max, 1e-6);
}

TEST(Rpe, ConstantTranslationalDriftPerSecond) {
  // Ground truth without rotation; the estimate drifts by v per second: E = (I, v * 1 s).
  Trajectory gt(200), est(200);
  const Eigen::Vector3d v(0.03, -0.04, 0.0);  // 0.05 m/s
  for (int k = 0; k < 200; ++k) {
    const double t = k * 0.05;
    gt[k].timestamp_s = est[k].timestamp_s = 10.0 + t;
    gt[k].world_from_cam.translation = Eigen::Vector3d(std::sin(t), std::cos(0.5 * t), 0.1 * t);
    est[k].world_from_cam.translation = gt[k].world_from_cam.translation + t * v;
  }
  const RpeResult r = ComputeRpe(gt, est, RpeOptions());
  ASSERT_GT(r.trans_m.count, 0);
  EXPECT_NEAR(r.trans_m.rmse, 0.05, 1e-12);
  EXPECT_NEAR(r.trans_m.min, 0.05, 1e-12);
  EXPECT_NEAR(r.trans_paper_form_m.rmse, 0.05, 1e-12);
  EXPECT_LT(r.rot_deg.max, 1e-9);
}

TEST(Rpe, ConstantRotationalDriftPerSecond) {
  // Camera at a fixed position turning about z; the estimate turns 2 deg/s faster.
  Trajectory gt(100), est(100);
  const double omega = 2.0 / kDegPerRad;
  for (int k = 0; k < 100; ++k) {
    const double t = k * 0.1;
    gt[k].timestamp_s = est[k].timestamp_s = t;
    gt[k].world_from_cam.rotation = Eigen::AngleAxisd(0.3 * t, Eigen::Vector3d::UnitZ());
    est[k].world_from_cam.rotation = Eigen::AngleAxisd((0.3 + omega) * t, Eigen::Vector3d::UnitZ());
  }
  const RpeResult r = ComputeRpe(gt, est, RpeOptions());
  ASSERT_GT(r.rot_deg.count, 0);
  EXPECT_NEAR(r.rot_deg.rmse, 2.0, 1e-9);
  EXPECT_NEAR(r.rot_deg.min, 2.0, 1e-9);
  EXPECT_LT(r.trans_m.max, 1e-12);
}

TEST(Rpe, PairsFollowEvaluateRpeRule) {
  // 31 poses at 0.0 .. 3.0 s: pose i pairs with the pose closest to t_i + 1 s; pairs whose second
  // pose is the last one (t = 3.0) are dropped, so i = 0 .. 19 remain.
  const Trajectory gt = Wiggle(31, 10.0, 0.0);
  const RpeResult r = ComputeRpe(gt, gt, RpeOptions());
  ASSERT_EQ(r.pairs.size(), 20u);
  for (size_t k = 0; k < r.pairs.size(); ++k) {
    EXPECT_EQ(r.pairs[k].est_i, static_cast<int>(k));
    EXPECT_EQ(r.pairs[k].est_j, static_cast<int>(k) + 10);
    EXPECT_EQ(r.pairs[k].gt_i, static_cast<int>(k));
  }
  EXPECT_NEAR(r.gt_max_time_difference_s, 0.2, 1e-9);
}

TEST(Rpe, GroundTruthMatchUsesTwiceTheMedianInterval) {
  // Ground truth has a 2 s hole; estimate poses inside it find no ground truth within 2 x 0.1 s.
  Trajectory gt;
  for (const StampedPose& p : Wiggle(101, 10.0, 0.0)) {
    if (p.timestamp_s < 4.0 || p.timestamp_s > 6.0) gt.push_back(p);
  }
  const Trajectory est = Wiggle(101, 10.0, 0.0);
  const RpeResult r = ComputeRpe(gt, est, RpeOptions());
  for (const RpePair& p : r.pairs) {
    for (int idx : {p.est_i, p.est_j}) {
      EXPECT_FALSE(est[idx].timestamp_s > 4.25 && est[idx].timestamp_s < 5.75) << idx;
    }
  }
  EXPECT_GT(r.pairs.size(), 40u);
}

TEST(Rpe, ScriptAndPaperFormsDifferOnlyInTranslation) {
  const Trajectory gt = Wiggle(200, 20.0);
  Trajectory est = gt;
  for (size_t k = 0; k < est.size(); ++k) {
    est[k].world_from_cam.rotation =
        est[k].world_from_cam.rotation *
        Eigen::Quaterniond(Eigen::AngleAxisd(0.02 * k, Eigen::Vector3d::UnitY()));
  }
  const RpeResult r = ComputeRpe(gt, est, RpeOptions());
  ASSERT_GT(r.pairs.size(), 0u);
  // Same positions, drifting orientation: t_A = R_est_i^T dp and t_B = R_gt_i^T dp differ, so
  // |t(A B^-1)| = |t_A - R_A R_B^T t_B| and |t(B^-1 A)| = |t_A - t_B| are non-zero and differ.
  EXPECT_GT(r.trans_m.rmse, 1e-3);
  EXPECT_GT(r.trans_paper_form_m.rmse, 1e-3);
  EXPECT_GT(std::abs(r.trans_m.rmse - r.trans_paper_form_m.rmse), 1e-6);
}

TEST(Rpe, ClosestIndexBreaksTiesAsEvaluateRpeDoes) {
  const std::vector<double> s = {0.0, 1.0, 2.0};
  EXPECT_EQ(ClosestIndex(s, 0.5), 0u);
  EXPECT_EQ(ClosestIndex(s, 0.6), 1u);
  EXPECT_EQ(ClosestIndex(s, -5.0), 0u);
  EXPECT_EQ(ClosestIndex(s, 9.0), 2u);
  EXPECT_EQ(ClosestIndex(s, 1.0), 1u);
  // evaluate_rpe.py's find_closest_index bisects 0..3: it visits 2 (0.5 away) before 1 (as far),
  // and keeps 2; in 0..2 above it visits 1 first (not closer than index 0) and keeps 0.
  const std::vector<double> four = {0.0, 1.0, 2.0, 3.0};
  EXPECT_EQ(ClosestIndex(four, 1.5), 2u);
  EXPECT_EQ(ClosestIndex(four, 0.5), 0u);
  EXPECT_EQ(ClosestIndex(four, 2.5), 2u);
}

// A pose is never paired with itself. Poses 2 s apart and delta 1 s: t_i + 1 s lies exactly
// between pose i and pose i + 1; pairing i with itself used to give a perfect 0.
TEST(Rpe, NeverPairsAPoseWithItself) {
  Trajectory gt(20), est(20);
  for (int k = 0; k < 20; ++k) {
    gt[k].timestamp_s = est[k].timestamp_s = 2.0 * k;
    gt[k].world_from_cam.translation = Eigen::Vector3d(0.5 * k, 0.0, 0.0);
    est[k].world_from_cam.translation = Eigen::Vector3d(0.6 * k, 0.0, 0.0);  // 0.1 m per pose
  }
  const RpeResult r = ComputeRpe(gt, est, RpeOptions());
  ASSERT_FALSE(r.pairs.empty());
  for (const RpePair& p : r.pairs) {
    EXPECT_EQ(p.est_j, p.est_i + 1);
    EXPECT_EQ(p.est_j, static_cast<int>(ClosestIndex(Stamps(est), 2.0 * p.est_i + 1.0)));
  }
  EXPECT_NEAR(r.trans_m.min, 0.1, 1e-12);
}

// A delta much shorter than the frame interval leaves only poses paired with themselves: no
// RPE, and the reason (the ATE is still computed: no error).
TEST(Rpe, DeltaShorterThanTheFrameIntervalGivesNoPairAndSaysWhy) {
  const Trajectory gt = Wiggle(50, 10.0);
  RpeOptions options;
  options.delta_s = 0.02;
  const RpeResult none = ComputeRpe(gt, gt, options);
  EXPECT_TRUE(none.pairs.empty());
  EXPECT_EQ(none.trans_m.count, 0);
  EXPECT_NE(none.no_pair_reason.find("RPE delta 0.02 s is shorter than the estimate's frame "
                                     "interval (median 0.1 s)"),
            std::string::npos)
      << none.no_pair_reason;
  options.delta_s = 0.08;  // closest to t_i + 0.08 s is pose i + 1
  EXPECT_EQ(ComputeRpe(gt, gt, options).pairs.size(), 48u);
}

TEST(Rpe, ShortTrajectoryGivesEmptyResult) {
  const Trajectory gt = Wiggle(5, 10.0);  // 0.4 s long, delta 1 s
  EXPECT_EQ(ComputeRpe(gt, gt, RpeOptions()).trans_m.count, 0);
}

}  // namespace
}  // namespace dynorb
