#include "dynorb/eval/alignment.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <random>

#include "dynorb/core/error.h"
#include "dynorb/core/test_expect_error.h"

namespace dynorb {
namespace {

// Horn (JOSA A 4(4), 1987): the rotation is the unit quaternion of the largest eigenvalue of the
// 4x4 matrix N built from the cross-covariance M = sum (est_i - mean)(gt_i - mean)^T; the scale
// (Horn's asymmetric form matching Umeyama) is trace(R M) / sum |est_i - mean|^2.
Similarity3d HornAlign(const Eigen::Matrix3Xd& est, const Eigen::Matrix3Xd& gt, bool with_scale) {
  const Eigen::Vector3d me = est.rowwise().mean(), mg = gt.rowwise().mean();
  const Eigen::Matrix3Xd a = est.colwise() - me, b = gt.colwise() - mg;
  const Eigen::Matrix3d m = a * b.transpose();
  const double sxx = m(0, 0), sxy = m(0, 1), sxz = m(0, 2), syx = m(1, 0), syy = m(1, 1),
               syz = m(1, 2), szx = m(2, 0), szy = m(2, 1), szz = m(2, 2);
  Eigen::Matrix4d n;
  n << sxx + syy + szz, syz - szy, szx - sxz, sxy - syx,  //
      syz - szy, sxx - syy - szz, sxy + syx, szx + sxz,   //
      szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy,  //
      sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> solver(n);
  const Eigen::Vector4d q = solver.eigenvectors().col(3);  // eigenvalues ascending
  Similarity3d s;
  s.rotation = Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized().toRotationMatrix();
  s.scale = with_scale ? (s.rotation * m).trace() / a.squaredNorm() : 1.0;
  s.translation = mg - s.scale * s.rotation * me;
  return s;
}

Eigen::Matrix3Xd RandomPoints(std::mt19937_64& rng, int n) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::Matrix3Xd p(3, n);
  for (int i = 0; i < n; ++i) p.col(i) = Eigen::Vector3d(2 * g(rng), g(rng), 0.5 * g(rng));
  return p;
}

TEST(Alignment, RecoversKnownRigidTransform) {
  std::mt19937_64 rng(1);
  const Eigen::Matrix3Xd gt = RandomPoints(rng, 50);
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(3, -1, 2);
  // est = R^T (gt - t), so gt = R est + t.
  const Eigen::Matrix3Xd est = r.transpose() * (gt.colwise() - t);
  const Similarity3d s = AlignPositions(est, gt, AlignmentMode::kSe3);
  EXPECT_LT((s.rotation - r).norm(), 1e-12);
  EXPECT_LT((s.translation - t).norm(), 1e-12);
  EXPECT_EQ(s.scale, 1.0);
}

TEST(Alignment, RecoversScaleWithSim3) {
  std::mt19937_64 rng(2);
  const Eigen::Matrix3Xd gt = RandomPoints(rng, 40);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d t(0.5, 0.2, -0.3);
  const double s_true = 2.5;  // gt = 2.5 R est + t
  const Eigen::Matrix3Xd est = (r.transpose() * (gt.colwise() - t)) / s_true;
  const Similarity3d s = AlignPositions(est, gt, AlignmentMode::kSim3);
  EXPECT_NEAR(s.scale, s_true, 1e-12);
  EXPECT_LT((s.rotation - r).norm(), 1e-12);
  EXPECT_LT((s.translation - t).norm(), 1e-12);
}

TEST(Alignment, EigenUmeyamaEqualsHornOnNoisyData) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3Xd gt = RandomPoints(rng, 30 + trial);
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(0.3 * trial, Eigen::Vector3d(1, trial, 2).normalized())
            .toRotationMatrix();
    Eigen::Matrix3Xd est = 0.8 * (r * gt);
    for (int i = 0; i < est.cols(); ++i)
      est.col(i) += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    for (bool with_scale : {false, true}) {
      const Similarity3d horn = HornAlign(est, gt, with_scale);
      const Similarity3d eig =
          AlignPositions(est, gt, with_scale ? AlignmentMode::kSim3 : AlignmentMode::kSe3);
      EXPECT_LT((horn.rotation - eig.rotation).norm(), 1e-10) << trial;
      EXPECT_LT((horn.translation - eig.translation).norm(), 1e-10) << trial;
      EXPECT_NEAR(horn.scale, eig.scale, 1e-10) << trial;
    }
  }
}

TEST(Alignment, NoneIsIdentityAndModesParse) {
  const Eigen::Matrix3Xd p = Eigen::Matrix3Xd::Random(3, 2);
  const Similarity3d s = AlignPositions(p, p * 2.0, AlignmentMode::kNone);
  EXPECT_TRUE(s.rotation.isIdentity());
  EXPECT_TRUE(s.translation.isZero());
  EXPECT_EQ(ParseAlignmentMode("se3"), AlignmentMode::kSe3);
  EXPECT_EQ(ParseAlignmentMode("sim3"), AlignmentMode::kSim3);
  EXPECT_EQ(ParseAlignmentMode("none"), AlignmentMode::kNone);
  EXPECT_THROW(ParseAlignmentMode("SE3x"), InputError);
  EXPECT_EQ(ToString(AlignmentMode::kSim3), "sim3");
}

TEST(Alignment, RejectsTooFewOrDegeneratePoints) {
  const Eigen::Matrix3Xd two = Eigen::Matrix3Xd::Random(3, 2);
  EXPECT_THROW(AlignPositions(two, two, AlignmentMode::kSe3), InputError);
  const Eigen::Matrix3Xd same = Eigen::Vector3d(1, 2, 3).replicate(1, 5);
  EXPECT_THROW(AlignPositions(same, same, AlignmentMode::kSim3), InputError);
}

// sim3 with a ground truth that has no spread, or whose motion does not correlate with the
// estimate's, has scale 0 (and used to give a NaN rotation): refused with a clear message.
TEST(Alignment, Sim3RefusesAGroundTruthWithoutSpreadOrCorrelation) {
  Eigen::Matrix3Xd est(3, 3), flat(3, 3), uncorrelated(3, 3);
  est << -1, 0, 1, 0.5, 0, -0.5, 0, 0, 0;
  flat = Eigen::Vector3d(4, 5, 6).replicate(1, 3);
  // Centred, gt x = (1, -2, 1) / 3 is orthogonal to every row of est: a zero cross-covariance.
  uncorrelated << 1, 0, 1, 0, 0, 0, 2, 2, 2;
  for (const Eigen::Matrix3Xd* gt : {&flat, &uncorrelated}) {
    dynorb::testing::ExpectInputError([&] { AlignPositions(est, *gt, AlignmentMode::kSim3); },
                                      "the ground-truth positions have no spread, or do not "
                                      "correlate with the estimate: no sim3 alignment");
    // se3 is defined: every rotation gives the same errors.
    const Similarity3d s = AlignPositions(est, *gt, AlignmentMode::kSe3);
    EXPECT_TRUE(s.rotation.allFinite());
    EXPECT_NEAR(s.rotation.determinant(), 1.0, 1e-12);
  }
}

// "All estimate positions identical" is relative to the coordinates' magnitude: 500 identical
// poses far from the origin (UTM-like) used to pass an absolute 1e-20 test and give a 180 deg
// alignment.
TEST(Alignment, IdenticalPositionsFarFromTheOriginAreRefused) {
  const Eigen::Matrix3Xd same = Eigen::Vector3d(500000.123, 5400000.456, 100.789).replicate(1, 500);
  std::mt19937_64 rng(4);
  const Eigen::Matrix3Xd moving = RandomPoints(rng, 500);
  for (AlignmentMode mode : {AlignmentMode::kSe3, AlignmentMode::kSim3}) {
    dynorb::testing::ExpectInputError([&] { AlignPositions(same, moving, mode); },
                                      "all associated estimate positions are identical");
  }
  dynorb::testing::ExpectInputError([&] { AlignPositions(moving, same, AlignmentMode::kSim3); },
                                    "no sim3 alignment");
}

// A real trajectory far from the origin still aligns (and precisely: the solver works relative
// to the first point).
TEST(Alignment, AlignsATrajectoryFarFromTheOrigin) {
  std::mt19937_64 rng(5);
  const Eigen::Vector3d far(500000.123, 5400000.456, 100.789);
  const Eigen::Matrix3Xd gt = RandomPoints(rng, 200).colwise() + far;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3Xd est = r.transpose() * (gt.colwise() - far);  // gt = R est + far
  for (AlignmentMode mode : {AlignmentMode::kSe3, AlignmentMode::kSim3}) {
    const Similarity3d s = AlignPositions(est, gt, mode);
    EXPECT_LT((s.rotation - r).norm(), 1e-9);
    EXPECT_NEAR(s.scale, 1.0, 1e-9);
    EXPECT_LT((s.translation - far).norm(), 1e-6);
  }
}

}  // namespace
}  // namespace dynorb
