// The FAST mode's cues on constructed data: a known F with injected moving points, flow fields
// with an independent mover, the rigid-warp residual and ego-motion under pure rotation and with a
// mover covering most of the image (LK correspondences: fast_correspondence_test.cc; regions and
// the suspect map: fast_region_test.cc).
#include "dynorb/dynamic/fast_cues.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <opencv2/imgproc.hpp>

#include "dynorb/dynamic/fast_region.h"
#include "dynorb/dynamic/motion_ego.h"
#include "dynorb/geometry/two_view.h"

namespace dynorb {
namespace {

PinholeCamera Camera() {
  PinholeCamera c;
  c.fx = c.fy = 525.0;
  c.cx = 319.5;
  c.cy = 239.5;
  c.width = 640;
  c.height = 480;
  return c;
}

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

// Rotation angle (rad) plus translation error (m) of an ego-motion estimate against the truth.
double MotionError(const EgoMotionResult& r, const Rigid3d& truth) {
  return RotationAngleRad(r.prev_from_cur.rotation * truth.rotation.conjugate()) +
         (r.prev_from_cur.translation - truth.translation).norm();
}

const Rigid3d kMotion(Eigen::Quaterniond(Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.2, 1.0, 0.1).normalized())),
                      Eigen::Vector3d(0.04, -0.01, 0.02));

TEST(EpipolarCue, KnownFundamentalWithInjectedMovers) {
  const PinholeCamera camera = Camera();
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
  const PinholeCamera camera = Camera();
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

// The ambiguity seen on synthetic walking_xyz: background at 3.3–5 m, the camera moves 1 cm
// sideways; a person at 2 m moves exactly as the background would if the camera had moved 6 cm
// and turned 0.7° (the turn cancels the extra parallax at 4 m). That wrong motion fits the person
// exactly and the background within 1.6 px, so at a 2 px gate it has the most inliers; only the
// true motion fits the background to the noise.
TEST(EgoMotion, TightGateRejectsAMotionThatExplainsBackgroundAndMoverTogether) {
  const PinholeCamera camera = Camera();
  const Rigid3d truth(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.01, 0.0, 0.0));  // prev_from_cur
  const Rigid3d alternative(Eigen::Quaterniond(Eigen::AngleAxisd(-0.05 / 4.0, Eigen::Vector3d::UnitY())),
                            Eigen::Vector3d(0.06, 0.0, 0.0));
  cv::Mat depth(camera.height, camera.width, CV_32F);
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      const uint32_t h = static_cast<uint32_t>((x / 8) * 73856093u ^ (y / 8) * 19349663u);
      depth.at<float>(y, x) = x < 200 ? 2.f : 3.3f + 1.7f * static_cast<float>(h % 1000) / 1000.f;
    }
  }
  std::vector<cv::Point2f> p1, p2;
  std::vector<uint8_t> valid;
  for (int y = 20; y < 460; y += 8) {
    for (int x = 20; x < 620; x += 8) {
      const cv::Point2f cur(static_cast<float>(x), static_cast<float>(y));  // block centres: no depth edge
      const float z = depth.at<float>(y, x);
      const cv::Point2f prev = WarpToPrevious(camera, x < 200 ? alternative : truth, cur, z);
      if (!camera.InImage(Eigen::Vector2d(prev.x, prev.y))) continue;
      p1.push_back(prev);
      p2.push_back(cur);
      valid.push_back(1);
    }
  }
  auto error = [&truth](const EgoMotionResult& r) { return MotionError(r, truth); };
  // From the wrong motion as the only seed, with the loose gates only: it stays wrong.
  EgoMotionOptions loose;
  loose.adaptive_iterations = 0;
  loose.min_gate_px = 2.0;
  loose.score_min_gate_px = 2.0;
  loose.try_identity = false;
  const EgoMotionResult wrong = EstimateEgoMotion(camera, p1, p2, valid, depth, {alternative}, loose);
  ASSERT_TRUE(wrong.ok);
  EXPECT_GT(error(wrong), 0.01);
  // Default: scored at the tight gate the wrong seed covers fewer cells; the camera-at-rest
  // hypothesis converges to the true motion and wins.
  const EgoMotionResult ego = EstimateEgoMotion(camera, p1, p2, valid, depth, {alternative}, EgoMotionOptions());
  ASSERT_TRUE(ego.ok);
  EXPECT_EQ(ego.seed_index, -2);  // the camera-at-rest hypothesis
  EXPECT_LT(error(ego), 1e-4);
  EXPECT_LE(ego.gate_px, 0.5 + 1e-9);
  // Limit (measured by review, 2026-11-30): this works while the tracking noise stays below the
  // wrong motion's misfit on the background — here up to ~0.1 px per axis; at 0.15 px the wrong
  // motion wins again. Synthetic LK noise is ~0.06 px; real data will be noisier.
}

// The true camera motion (prev_from_cur) and a person's, for the dominant-mover scenes below.
const Rigid3d kDominantTruth(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.007, 0.0, -0.003));
const Rigid3d kDominantPerson(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.025, 0.0, 0.02));

// Background at 4 m over coverage columns 0..2, a person at 1.5 m over columns 3..7 (30 of the 48
// cells of 80 px), 4 tracked points per cell, each side with its own LK noise (px per axis).
struct DominantMoverScene {
  cv::Mat depth;
  std::vector<cv::Point2f> p1, p2;
  std::vector<uint8_t> valid;
};
DominantMoverScene MakeDominantMoverScene(const PinholeCamera& camera, float background_noise_px,
                                          float person_noise_px) {
  constexpr int kMoverX = 240;
  DominantMoverScene scene;
  scene.depth.create(camera.height, camera.width, CV_32F);
  for (int y = 0; y < scene.depth.rows; ++y) {
    for (int x = 0; x < scene.depth.cols; ++x) scene.depth.at<float>(y, x) = x < kMoverX ? 4.f : 1.5f;
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> within(12.f, 68.f);  // inside an 80 px cell, away from edges
  std::normal_distribution<float> bg_noise(0.f, background_noise_px), person_noise(0.f, person_noise_px);
  for (int cy = 0; cy < 6; ++cy) {
    for (int cx = 0; cx < 8; ++cx) {
      for (int k = 0; k < 4; ++k) {
        const cv::Point2f cur(80.f * cx + within(rng), 80.f * cy + within(rng));
        const bool on_person = cur.x >= kMoverX;
        cv::Point2f prev =
            WarpToPrevious(camera, on_person ? kDominantPerson : kDominantTruth, cur, on_person ? 1.5 : 4.0);
        prev += on_person ? cv::Point2f(person_noise(rng), person_noise(rng))
                          : cv::Point2f(bg_noise(rng), bg_noise(rng));
        scene.p1.push_back(prev);
        scene.p2.push_back(cur);
        scene.valid.push_back(1);
      }
    }
  }
  return scene;
}

// The ego-motion of a dominant-mover scene, with the true motion as the prediction.
EgoMotionResult EstimateInScene(const PinholeCamera& camera, const DominantMoverScene& scene,
                                const EgoMotionOptions& options) {
  return EstimateEgoMotion(camera, scene.p1, scene.p2, scene.valid, scene.depth, {kDominantTruth}, options);
}

// A walking person filling most of the view (30 of the 48 coverage cells, 120 points) fits a
// rigid motion only loosely (a body is not rigid: 0.35 px per axis here), the background (18
// cells, 72 points) to the tracking noise (0.05 px); the prediction is right. Scored at a 0.5 px
// floor, most of the person's cells count as covered and it wins; at the default 0.3 px floor
// (3 sigmas of the background's fit) fewer than half of its points fit in most cells, and the
// prediction is kept (the case of full-length walking_xyz s7, frames 825-830).
TEST(EgoMotion, ALooselyFittingDominantMoverDoesNotOutvoteACorrectPrediction) {
  const PinholeCamera camera = Camera();
  const Rigid3d& truth = kDominantTruth;
  const DominantMoverScene scene = MakeDominantMoverScene(camera, 0.05f, 0.35f);
  auto error = [&truth](const EgoMotionResult& r) { return MotionError(r, truth); };
  const EgoMotionResult ego = EstimateInScene(camera, scene, EgoMotionOptions());
  ASSERT_TRUE(ego.ok);
  EXPECT_EQ(ego.seed_index, 0);
  EXPECT_LT(error(ego), 2e-3);
  EXPECT_LT(ego.gate_px, 0.5);
  // The floor of before (and no rigidity rule): the person's motion wins.
  EgoMotionOptions old_floor;
  old_floor.score_min_gate_px = 0.5;
  old_floor.seed_rigidity_ratio = 0.0;
  const EgoMotionResult captured = EstimateInScene(camera, scene, old_floor);
  ASSERT_TRUE(captured.ok);
  EXPECT_EQ(captured.seed_index, -1);
  EXPECT_GT(error(captured), 0.02);
}

// The geometry above with a person fitting a rigid motion to 0.2 px per axis and the background to
// 0.1 px (as on full-length walking_xyz s7, frames 825-829: 0.22-0.26 against 0.13 px): at the
// common gate (3 x the tightest spread, 0.5 px) both cover their cells and the person, larger,
// wins on coverage alone; the prediction fits about twice as tightly and wins by rigidity.
TEST(EgoMotion, AMoreRigidPredictionWinsOverALargerLooselyFittingMover) {
  const PinholeCamera camera = Camera();
  const Rigid3d& truth = kDominantTruth;
  const DominantMoverScene scene = MakeDominantMoverScene(camera, 0.1f, 0.2f);
  const EgoMotionResult ego = EstimateInScene(camera, scene, EgoMotionOptions());
  ASSERT_TRUE(ego.ok);
  EXPECT_EQ(ego.seed_index, 0);
  // The flat background at 4 m with 0.1 px noise trades a little translation for rotation; the
  // person's motion is 0.04 away.
  EXPECT_LT(MotionError(ego, truth), 5e-3);
  // Coverage alone: the larger person wins.
  EgoMotionOptions coverage_only;
  coverage_only.seed_rigidity_ratio = 0.0;
  const EgoMotionResult captured = EstimateInScene(camera, scene, coverage_only);
  ASSERT_TRUE(captured.ok);
  EXPECT_EQ(captured.seed_index, -1);
  EXPECT_GT(MotionError(captured, truth), 0.02);
}

TEST(WarpResidual, NoMotionAndDepthChange) {
  const PinholeCamera camera = Camera();
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
  const PinholeCamera camera = Camera();
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
