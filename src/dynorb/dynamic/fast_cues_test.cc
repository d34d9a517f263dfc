// The FAST mode's cues on constructed data: a known F with injected moving points, flow fields
// with an independent mover, the rigid-warp residual and ego-motion under pure rotation and with a
// mover covering most of the image (LK correspondences: fast_correspondence_test.cc; regions and
// the suspect map: fast_region_test.cc; the ego-motion's choice between hypotheses:
// motion_ego_test.cc).
#include "dynorb/dynamic/fast_cues.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <opencv2/imgproc.hpp>

#include "dynorb/dynamic/fast_region.h"
#include "dynorb/dynamic/fast_test_util.h"
#include "dynorb/dynamic/motion_ego.h"
#include "dynorb/geometry/two_view.h"

namespace dynorb {
namespace {

// A static scene seen from two poses: points p1 (previous) and p2 (current), depth of p2.
struct TwoViews {
  std::vector<cv::Point2f> p1, p2;
  std::vector<float> z2;
  std::vector<uint8_t> valid;
};

TwoViews MakeStatic(const PinholeCamera& camera, const Rigid3d& cur_from_prev, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(20.0, 620.0), v(20.0, 460.0), d(1.5, 5.0);
  TwoViews views;
  while (static_cast<int>(views.p1.size()) < n) {
    const Eigen::Vector3d x_prev = camera.Unproject(Eigen::Vector2d(u(rng), v(rng)), d(rng));
    const Eigen::Vector3d x_cur = cur_from_prev * x_prev;
    const Eigen::Vector2d a = camera.Project(x_prev), b = camera.Project(x_cur);
    if (!camera.InImage(b)) continue;
    views.p1.emplace_back(a.x(), a.y());
    views.p2.emplace_back(b.x(), b.y());
    views.z2.push_back(static_cast<float>(x_cur.z()));
    views.valid.push_back(1);
  }
  return views;
}

const Rigid3d kMotion(Eigen::Quaterniond(Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.2, 1.0, 0.1).normalized())),
                      Eigen::Vector3d(0.04, -0.01, 0.02));

TEST(EpipolarCue, KnownFundamentalWithInjectedMovers) {
  const PinholeCamera camera = FastTestCamera();
  TwoViews v = MakeStatic(camera, kMotion, 200, 1);
  const Eigen::Matrix3d f = FundamentalFromMotion(camera, kMotion);
  // Movers: shift 40 points by 6 px perpendicular to their epipolar line; 10 gross mismatches.
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d line = f * Eigen::Vector3d(v.p1[i].x, v.p1[i].y, 1.0);
    const Eigen::Vector2d normal = line.head<2>().normalized();
    const double shift = i < 40 ? 6.0 : 80.0;
    v.p2[i] += cv::Point2f(static_cast<float>(shift * normal.x()), static_cast<float>(shift * normal.y()));
    EXPECT_NEAR(EpipolarDistancePx(f, Eigen::Vector2d(v.p1[i].x, v.p1[i].y), Eigen::Vector2d(v.p2[i].x, v.p2[i].y)),
                shift, 1e-3);
  }
  v.valid[199] = 0;
  const std::vector<CueVote> votes = EpipolarCue(f, v.p1, v.p2, v.valid, 1.5, 30.0);
  for (int i = 0; i < 200; ++i) {
    const CueVote expected = i == 199  ? CueVote::kUnknown
                             : i < 40  ? CueVote::kMoving
                             : i < 50  ? CueVote::kMismatch
                                       : CueVote::kStatic;
    EXPECT_EQ(static_cast<int>(votes[i]), static_cast<int>(expected)) << i;
  }
  // No epipolar line at all (degenerate F): no evidence either way, not "static".
  for (CueVote vote : EpipolarCue(Eigen::Matrix3d::Zero(), v.p1, v.p2, v.valid, 1.5, 30.0))
    EXPECT_EQ(static_cast<int>(vote), static_cast<int>(CueVote::kUnknown));
}

// Uniform camera flow with an independent mover in one corner.
TEST(DirectionCue, IndependentMoverInUniformFlow) {
  std::vector<cv::Point2f> p1, p2;
  std::vector<uint8_t> valid, ref;
  for (int y = 10; y < 480; y += 20) {
    for (int x = 10; x < 640; x += 20) {
      const bool mover = x > 400 && y > 300;
      const cv::Point2f flow = mover ? cv::Point2f(0.f, 5.f) : cv::Point2f(4.f, 0.5f);
      p2.emplace_back(static_cast<float>(x), static_cast<float>(y));
      p1.push_back(p2.back() - flow);
      valid.push_back(1);
      ref.push_back(mover ? 0 : 1);  // static inliers (as F-RANSAC would give)
    }
  }
  const std::vector<CueVote> votes = DirectionCue(p1, p2, valid, ref, 30.0, 1.0);
  for (size_t i = 0; i < votes.size(); ++i) {
    const bool mover = p2[i].x > 400 && p2[i].y > 300;
    EXPECT_EQ(static_cast<int>(votes[i]), static_cast<int>(mover ? CueVote::kMoving : CueVote::kStatic)) << i;
  }
  // Flows too short to have a direction give no vote.
  const std::vector<CueVote> none = DirectionCue(p2, p2, valid, ref, 30.0, 1.0);
  for (CueVote v : none) EXPECT_EQ(static_cast<int>(v), static_cast<int>(CueVote::kUnknown));
  // Nor with no minimum length (0 / 0 gave a static vote before session 54).
  const std::vector<CueVote> still = DirectionCue(p2, p2, valid, ref, 30.0, 0.0);
  for (CueVote v : still) EXPECT_EQ(static_cast<int>(v), static_cast<int>(CueVote::kUnknown));
}

TEST(MagnitudeCue, OutliersBeyondTwoSigmaAndSmallSigmaFallback) {
  std::vector<cv::Point2f> p1, p2;
  std::vector<uint8_t> valid;
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.f, 0.3f);
  for (int i = 0; i < 300; ++i) {
    const float m = i < 15 ? 14.f : 5.f + noise(rng);
    p2.emplace_back(100.f + i, 200.f);
    p1.push_back(p2.back() - cv::Point2f(m, 0.f));
    valid.push_back(1);
  }
  MagnitudeStats stats;
  const std::vector<CueVote> votes = MagnitudeCue(p1, p2, valid, 2.0, 0.5, 2.0, &stats);
  EXPECT_GT(stats.sigma_px, 0.5);
  for (int i = 0; i < 15; ++i) EXPECT_EQ(static_cast<int>(votes[i]), static_cast<int>(CueVote::kMoving)) << i;
  int false_moving = 0;
  for (int i = 15; i < 300; ++i) false_moving += votes[i] == CueVote::kMoving;
  EXPECT_LE(false_moving, 15);  // ~5 % of a normal sample beyond 2 sigma at most
  // No camera motion: sigma 0 -> the plain difference decides; one point moves 3 px.
  std::vector<cv::Point2f> q1 = p2;
  q1[7] += cv::Point2f(3.f, 0.f);
  const std::vector<CueVote> still = MagnitudeCue(q1, p2, valid, 2.0, 0.5, 2.0, &stats);
  EXPECT_LT(stats.sigma_px, 0.5);
  for (int i = 0; i < 300; ++i) {
    EXPECT_EQ(static_cast<int>(still[i]), static_cast<int>(i == 7 ? CueVote::kMoving : CueVote::kStatic)) << i;
  }
}

// Dense depth map of a static scene rendered in the current camera: a plane at depth z.
cv::Mat PlaneDepth(float z) { return cv::Mat(480, 640, CV_32F, cv::Scalar(z)); }

// Pure rotation (no parallax: F is degenerate) with a mover covering 55 % of the points: the
// prediction-seeded ego-motion recovers the rotation and the residual flags exactly the mover.
TEST(WarpResidual, PureRotationAndDominantMover) {
  const PinholeCamera camera = FastTestCamera();
  const Rigid3d cur_from_prev(Eigen::Quaterniond(Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitY())),
                              Eigen::Vector3d::Zero());
  const Rigid3d prev_from_cur = cur_from_prev.Inverse();
  const cv::Mat depth = PlaneDepth(3.f);
  std::vector<cv::Point2f> p1, p2;
  std::vector<uint8_t> valid;
  std::vector<bool> mover;
  for (int y = 12; y < 470; y += 16) {
    for (int x = 12; x < 630; x += 16) {
      const cv::Point2f cur(static_cast<float>(x), static_cast<float>(y));
      cv::Point2f prev = WarpToPrevious(camera, prev_from_cur, cur, 3.0);
      const bool m = x < 340;  // ~55 % of the image
      if (m) prev += cv::Point2f(-6.f, 2.f);  // the mover's own motion
      if (!camera.InImage(Eigen::Vector2d(prev.x, prev.y))) continue;
      p1.push_back(prev);
      p2.push_back(cur);
      valid.push_back(1);
      mover.push_back(m);
    }
  }
  // A prediction that is off by 0.3 degrees.
  const Rigid3d predicted =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.005, Eigen::Vector3d::UnitX())), Eigen::Vector3d::Zero()) *
      prev_from_cur;
  const EgoMotionResult ego = EstimateEgoMotion(camera, p1, p2, valid, depth, {predicted}, EgoMotionOptions());
  ASSERT_TRUE(ego.ok);
  EXPECT_LT(RotationAngleRad(ego.prev_from_cur.rotation * prev_from_cur.rotation.conjugate()), 1e-3);
  EXPECT_LT(ego.prev_from_cur.translation.norm(), 0.01);
  const WarpResidualResult r =
      WarpResidualCue(camera, ego.prev_from_cur, p1, p2, valid, depth, cv::Mat(), WarpResidualOptions());
  for (size_t i = 0; i < p1.size(); ++i) {
    EXPECT_EQ(static_cast<int>(r.residual[i]), static_cast<int>(mover[i] ? CueVote::kMoving : CueVote::kStatic))
        << i;
  }
  // Without a prediction: PnP-RANSAC at 3 px takes the majority (the mover) first, but the mover's
  // image shift is not a rigid motion of the plane, so it fits ~0.1 px worse than the background;
  // scored at the common tight gate, the background (exact) covers more cells and wins.
  const EgoMotionResult blind = EstimateEgoMotion(camera, p1, p2, valid, depth, {}, EgoMotionOptions());
  ASSERT_TRUE(blind.ok);
  EXPECT_EQ(blind.seed_index, -1);
  EXPECT_LT(RotationAngleRad(blind.prev_from_cur.rotation * prev_from_cur.rotation.conjugate()) +
                (blind.prev_from_cur.translation - prev_from_cur.translation).norm(),
            1e-4);
  EXPECT_LT(blind.sigma_px, 0.01);
  // With the loose 2 px scoring gate of before (no adaptive gate), the majority wins.
  EgoMotionOptions loose;
  loose.adaptive_iterations = 0;
  loose.min_gate_px = 2.0;
  loose.score_min_gate_px = 2.0;
  const EgoMotionResult majority = EstimateEgoMotion(camera, p1, p2, valid, depth, {}, loose);
  ASSERT_TRUE(majority.ok);
  EXPECT_GT(RotationAngleRad(majority.prev_from_cur.rotation * prev_from_cur.rotation.conjugate()) +
                (majority.prev_from_cur.translation - prev_from_cur.translation).norm(),
            1e-3);
}

TEST(WarpResidual, NoMotionAndDepthChange) {
  const PinholeCamera camera = FastTestCamera();
  const cv::Mat depth = PlaneDepth(2.f);
  cv::Mat depth_prev = depth.clone();
  depth_prev(cv::Rect(300, 200, 60, 60)).setTo(2.4f);  // something moved towards the camera there
  std::vector<cv::Point2f> p;
  std::vector<uint8_t> valid;
  for (int y = 20; y < 470; y += 20)
    for (int x = 20; x < 630; x += 20) p.emplace_back(static_cast<float>(x), static_cast<float>(y)), valid.push_back(1);
  const WarpResidualResult r = WarpResidualCue(camera, Rigid3d(), p, p, valid, depth, depth_prev, WarpResidualOptions());
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_EQ(static_cast<int>(r.residual[i]), static_cast<int>(CueVote::kStatic));
    const bool inside = p[i].x >= 302 && p[i].x <= 357 && p[i].y >= 202 && p[i].y <= 257;
    EXPECT_EQ(static_cast<int>(r.depth[i]), static_cast<int>(inside ? CueVote::kMoving : CueVote::kStatic)) << p[i];
  }
}

// Per-point tolerance (matched keypoints from coarse pyramid levels) and the mismatch bound.
TEST(WarpResidual, ToleranceScaleAndMismatch) {
  const PinholeCamera camera = FastTestCamera();
  const cv::Mat depth = PlaneDepth(2.f);
  // No camera motion; the "previous" positions are off by 0, 2, 2 and 60 px.
  const std::vector<cv::Point2f> p2 = {{100.f, 100.f}, {200.f, 100.f}, {300.f, 100.f}, {400.f, 100.f}};
  const std::vector<cv::Point2f> p1 = {{100.f, 100.f}, {202.f, 100.f}, {302.f, 100.f}, {460.f, 100.f}};
  const std::vector<uint8_t> valid(4, 1);
  WarpResidualOptions o;
  o.residual_px = 1.2;
  o.residual_rel = 0.0;
  o.mismatch_px = 40.0;
  const std::vector<float> scale = {1.f, 1.f, 2.0736f, 1.f};  // third point: level 4 of 1.2
  o.tolerance_scale = &scale;
  const WarpResidualResult r = WarpResidualCue(camera, Rigid3d(), p1, p2, valid, depth, depth, o);
  EXPECT_EQ(static_cast<int>(r.residual[0]), static_cast<int>(CueVote::kStatic));
  EXPECT_EQ(static_cast<int>(r.residual[1]), static_cast<int>(CueVote::kMoving));
  EXPECT_EQ(static_cast<int>(r.residual[2]), static_cast<int>(CueVote::kStatic));  // 2 px < 1.2 * 2.07
  EXPECT_EQ(static_cast<int>(r.residual[3]), static_cast<int>(CueVote::kMismatch));
  EXPECT_EQ(static_cast<int>(r.depth[3]), static_cast<int>(CueVote::kUnknown));  // no evidence at all
  EXPECT_NEAR(r.residual_px[3], 60.f, 1e-3f);
}

}  // namespace
}  // namespace dynorb
