// LK correspondences of the FAST mode (fast_correspondence.h) on constructed images: the
// forward-backward check on a subset, the base-image-first tracking with its retracks, and the
// spread subset of keypoints.
#include "dynorb/dynamic/fast_correspondence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace dynorb {
namespace {

// Forward tracks only, then the backward check on a subset: a track moved off its true position
// fails the check and is invalidated; good tracks and points outside the subset are untouched.
TEST(LkFlow, BackwardCheckOnASubsetInvalidatesOnlyBadTracks) {
  cv::Mat noise(240, 320, CV_8U);
  cv::randu(noise, 0, 255);
  cv::Mat texture;
  cv::GaussianBlur(noise, texture, cv::Size(0, 0), 2.0);
  cv::resize(texture, texture, cv::Size(640, 480));
  cv::normalize(texture, texture, 0, 255, cv::NORM_MINMAX);
  cv::Mat previous = texture, current;
  const cv::Mat shift =
      (cv::Mat_<double>(2, 3) << 1, 0, 3, 0, 1, 1);  // current = previous moved (3, 1)
  cv::warpAffine(previous, current, shift, previous.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  LkOptions lk;
  lk.backward_check = false;
  const std::vector<cv::Mat> prev_pyr = BuildLkPyramid(previous, lk),
                             cur_pyr = BuildLkPyramid(current, lk);
  std::vector<cv::Point2f> points;
  for (int y = 60; y < 420; y += 40)
    for (int x = 60; x < 580; x += 40)
      points.emplace_back(static_cast<float>(x), static_cast<float>(y));
  Correspondences c = TrackWithFlow(prev_pyr, cur_pyr, points, {}, lk);
  ASSERT_EQ(c.num_valid, static_cast<int>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(c.previous[i].x, points[i].x - 3.f, 0.1f);
    EXPECT_NEAR(c.previous[i].y, points[i].y - 1.f, 0.1f);
  }
  // Corrupt every third track by 6 px; check the even indices only.
  std::vector<int> subset;
  for (size_t i = 0; i < points.size(); ++i) {
    if (i % 3 == 0) c.previous[i] += cv::Point2f(6.f, -6.f);
    if (i % 2 == 0) subset.push_back(static_cast<int>(i));
  }
  // The check through two levels (the FAST default) finds the same bad tracks as through four.
  LkOptions two_levels = lk;
  two_levels.backward_levels = 1;
  Correspondences c2 = c;
  EXPECT_EQ(CheckBackward(prev_pyr, cur_pyr, points, subset, two_levels, &c2),
            static_cast<int>((subset.size() + 2) / 3));
  const int invalidated = CheckBackward(prev_pyr, cur_pyr, points, subset, lk, &c);
  EXPECT_EQ(c2.valid, c.valid);
  int expected = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const bool checked_bad = i % 3 == 0 && i % 2 == 0;
    expected += checked_bad;
    EXPECT_EQ(c.valid[i], checked_bad ? 0 : 1) << i;
    EXPECT_EQ(c.for_f[i], checked_bad ? 0 : 1) << i;
  }
  EXPECT_EQ(invalidated, expected);
  EXPECT_EQ(c.num_valid, static_cast<int>(points.size()) - expected);
  // Tracking a subset: only the listed points get correspondences.
  const Correspondences part = TrackSubsetWithFlow(prev_pyr, cur_pyr, points, subset, {}, lk);
  ASSERT_EQ(part.valid.size(), points.size());
  EXPECT_EQ(part.num_valid, static_cast<int>(subset.size()));
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(part.valid[i], i % 2 == 0 ? 1 : 0) << i;
    const cv::Point2f expect = i % 2 == 0 ? points[i] - cv::Point2f(3.f, 1.f) : points[i];
    EXPECT_NEAR(part.previous[i].x, expect.x, 0.1f);
    EXPECT_NEAR(part.previous[i].y, expect.y, 0.1f);
  }
}

// A textured image pair shifted by (3, 1) px, and one guess per point: good_offset (0.5 px) off
// for most, far off (a mover the prediction does not know) for the right third of the points.
struct BaseFirstScene {
  std::vector<cv::Mat> prev_pyr, cur_pyr;
  std::vector<cv::Point2f> points, guess;
  std::vector<bool> bad;
  LkOptions pyramid_only;
};

BaseFirstScene MakeBaseFirstScene(cv::Point2f good_offset = {0.4f, -0.3f}) {
  BaseFirstScene s;
  cv::Mat noise(240, 320, CV_8U);
  cv::RNG rng(20261203);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat texture;
  cv::GaussianBlur(noise, texture, cv::Size(0, 0), 2.0);
  cv::resize(texture, texture, cv::Size(640, 480));
  cv::normalize(texture, texture, 0, 255, cv::NORM_MINMAX);
  cv::Mat previous = texture.clone(), current;
  const cv::Mat shift =
      (cv::Mat_<double>(2, 3) << 1, 0, 3, 0, 1, 1);  // current = previous moved (3, 1)
  cv::warpAffine(texture, current, shift, texture.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  // Decoys: at some bad guesses the previous image holds a faint copy of the point's patch, so the
  // base level stops at the guess (same shape) with a large residual (half the contrast).
  const cv::Point2f bad_offset(12.f, -9.f);
  for (int y = 100; y < 380; y += 60) {
    const cv::Rect patch(420 - 10, y - 10, 21, 21);
    const cv::Rect decoy = patch + cv::Point(-3, -1) + cv::Point(bad_offset);
    cv::Mat faint;
    current(patch).convertTo(faint, CV_8U, 0.5, 64.0);
    faint.copyTo(previous(decoy));
  }
  s.pyramid_only.backward_check = false;
  s.prev_pyr = BuildLkPyramid(previous, s.pyramid_only);
  s.cur_pyr = BuildLkPyramid(current, s.pyramid_only);
  for (int y = 100; y < 380; y += 20) {
    for (int x = 100; x < 540; x += 20) {
      s.points.emplace_back(static_cast<float>(x), static_cast<float>(y));
      s.bad.push_back(x >= 400);
      s.guess.push_back(s.points.back() - cv::Point2f(3.f, 1.f) +
                        (s.bad.back() ? bad_offset : good_offset));
    }
  }
  return s;
}

// Base image first: from a good guess the base-level pass gives the whole pyramid's answer; a
// guess far off is tracked again through the pyramid, also where the base level got stuck near
// the guess.
TEST(LkFlow, BaseFirstKeepsGoodGuessesAndRetracksTheRestThroughThePyramid) {
  const BaseFirstScene s = MakeBaseFirstScene();
  const std::vector<cv::Point2f>& points = s.points;
  LkOptions base_first = s.pyramid_only;
  base_first.base_first_px = 1.0;
  LkOptions base_only = s.pyramid_only;
  base_only.levels = 0;
  const Correspondences full =
      TrackWithFlow(s.prev_pyr, s.cur_pyr, points, s.guess, s.pyramid_only);
  const Correspondences fast = TrackWithFlow(s.prev_pyr, s.cur_pyr, points, s.guess, base_first);
  const Correspondences base = TrackWithFlow(s.prev_pyr, s.cur_pyr, points, s.guess, base_only);
  ASSERT_EQ(fast.num_valid, full.num_valid);
  int num_bad = 0, base_wrong = 0, base_stuck = 0, right = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(fast.valid[i], full.valid[i]) << i;
    if (!full.valid[i]) continue;
    // The whole pyramid's answer, good guess or bad.
    EXPECT_NEAR(fast.previous[i].x, full.previous[i].x, 0.02f) << i;
    EXPECT_NEAR(fast.previous[i].y, full.previous[i].y, 0.02f) << i;
    const cv::Point2f truth = points[i] - cv::Point2f(3.f, 1.f);
    const cv::Point2f e = full.previous[i] - truth, b = base.previous[i] - full.previous[i];
    const cv::Point2f g = base.previous[i] - s.guess[i];
    right += std::hypot(e.x, e.y) < 0.1f;
    num_bad += s.bad[i];
    base_wrong += s.bad[i] && (!base.valid[i] || std::hypot(b.x, b.y) > 0.1f);
    base_stuck +=
        s.bad[i] && base.valid[i] && std::hypot(g.x, g.y) <= 1.f && std::hypot(b.x, b.y) > 0.5f;
  }
  EXPECT_GT(right, static_cast<int>(points.size()) * 9 / 10);  // the pyramid finds the shift
  // The base level alone does not bridge many of the bad guesses: the retracking finds them.
  EXPECT_GT(base_wrong, num_bad / 4);
  // At the decoys it stops within base_first_px of the guess: only its residual sends it back.
  EXPECT_GE(base_stuck, 1);
}

// A prediction error every point shares (here 2 px, as a camera's rotation jitter gives): without
// the shift every point ends more than base_first_px from its guess and is tracked again; with it
// hardly more than the far-off guesses are, and the tracks are the whole pyramid's.
TEST(LkFlow, ASharedPredictionErrorIsRemovedBeforeTheRetrackTest) {
  const BaseFirstScene s = MakeBaseFirstScene({1.6f, -1.2f});
  LkOptions plain = s.pyramid_only;
  plain.base_first_px = 1.0;
  plain.base_window_px = 11;
  LkOptions shifted = plain;
  shifted.base_shift_min_points = 20;
  const Correspondences full =
      TrackWithFlow(s.prev_pyr, s.cur_pyr, s.points, s.guess, s.pyramid_only);
  const Correspondences without = TrackWithFlow(s.prev_pyr, s.cur_pyr, s.points, s.guess, plain);
  const Correspondences with = TrackWithFlow(s.prev_pyr, s.cur_pyr, s.points, s.guess, shifted);
  const int n = static_cast<int>(s.points.size());
  const int num_bad = static_cast<int>(std::count(s.bad.begin(), s.bad.end(), true));
  EXPECT_EQ(without.num_retracked, n);
  // The far-off guesses (a few good ones may miss the residual gate of the 11 px window).
  EXPECT_GE(with.num_retracked, num_bad);
  EXPECT_LE(with.num_retracked, num_bad + n / 20);
  EXPECT_EQ(full.num_retracked, 0);  // no base-image pass
  ASSERT_EQ(with.num_valid, full.num_valid);
  int right = 0;
  for (int i = 0; i < n; ++i) {
    ASSERT_EQ(with.valid[i], full.valid[i]) << i;
    if (!with.valid[i]) continue;
    const cv::Point2f d = with.previous[i] - full.previous[i];
    EXPECT_LT(std::hypot(d.x, d.y), 0.05f) << i;
    const cv::Point2f e = with.previous[i] - (s.points[i] - cv::Point2f(3.f, 1.f));
    right += std::hypot(e.x, e.y) < 0.1f;
  }
  EXPECT_GT(right, n * 9 / 10);
  // Too few converged points for a median: no shift, every point is tracked again.
  shifted.base_shift_min_points = n + 1;
  EXPECT_EQ(TrackWithFlow(s.prev_pyr, s.cur_pyr, s.points, s.guess, shifted).num_retracked, n);
}

// Tracks of `variant` against those of `reference` on the scene: the same points valid, how many
// find the true shift within 0.1 px, and the largest difference to the reference's tracks.
struct TrackComparison {
  int right = 0;
  float max_difference = 0.f;
};
TrackComparison CompareTracks(const BaseFirstScene& s, const LkOptions& reference_options,
                              const LkOptions& variant) {
  const Correspondences reference =
      TrackWithFlow(s.prev_pyr, s.cur_pyr, s.points, s.guess, reference_options);
  const Correspondences c = TrackWithFlow(s.prev_pyr, s.cur_pyr, s.points, s.guess, variant);
  TrackComparison out;
  EXPECT_EQ(c.num_valid, reference.num_valid);
  for (size_t i = 0; i < s.points.size(); ++i) {
    EXPECT_EQ(c.valid[i], reference.valid[i]) << i;
    if (!c.valid[i] || !reference.valid[i]) continue;
    const cv::Point2f d = c.previous[i] - reference.previous[i];
    out.max_difference = std::max(out.max_difference, std::hypot(d.x, d.y));
    const cv::Point2f e = c.previous[i] - (s.points[i] - cv::Point2f(3.f, 1.f));
    out.right += std::hypot(e.x, e.y) < 0.1f;
  }
  return out;
}

// The base-image pass with a smaller window (lk_base_window_px: 11, a quarter of the 21 px
// window's pixels): the good guesses converge to the same answer, the bad ones (decoys included)
// are still sent to the retrack, which runs with the full window.
TEST(LkFlow, ASmallerBaseWindowGivesTheFullWindowsTracks) {
  const BaseFirstScene s = MakeBaseFirstScene();
  LkOptions base_first = s.pyramid_only;
  base_first.base_first_px = 1.0;
  LkOptions small = base_first;
  small.base_window_px = 11;
  const TrackComparison c = CompareTracks(s, base_first, small);
  EXPECT_LT(c.max_difference, 0.05f);
  EXPECT_GT(c.right, static_cast<int>(s.points.size()) * 9 / 10);
  // The small window did run: its sub-pixel answers are not bit-identical to the 21 px window's.
  EXPECT_GT(c.max_difference, 1e-4f) << c.max_difference;
}

// A coarser stopping step (lk_epsilon_px 0.05 instead of 0.01): LK stops earlier, the tracks stay
// within a tenth of a pixel of the finer ones, and the far-off guesses still find the shift.
TEST(LkFlow, ACoarserStopKeepsTheTracksWithinATenthOfAPixel) {
  const BaseFirstScene s = MakeBaseFirstScene();
  LkOptions fine = s.pyramid_only;
  fine.base_first_px = 1.0;
  fine.base_window_px = 11;
  LkOptions coarse = fine;
  coarse.epsilon_px = 0.05;
  const TrackComparison c = CompareTracks(s, fine, coarse);
  EXPECT_LT(c.max_difference, 0.1f);
  EXPECT_GT(c.max_difference, 1e-4f) << "the coarser step should stop some points earlier";
  EXPECT_GT(c.right, static_cast<int>(s.points.size()) * 9 / 10);
}

TEST(LkFlow, SpreadSubsetTakesTheStrongestOfEveryCellFirst) {
  std::vector<cv::KeyPoint> keypoints;
  // Cell (0, 0) of the 16x12 grid on 640x480 (40x40 px): three keypoints; three other cells: one
  // each.
  keypoints.emplace_back(cv::Point2f(5.f, 5.f), 7.f, -1.f, 10.f);     // 0
  keypoints.emplace_back(cv::Point2f(15.f, 5.f), 7.f, -1.f, 30.f);    // 1 strongest of cell (0, 0)
  keypoints.emplace_back(cv::Point2f(25.f, 5.f), 7.f, -1.f, 20.f);    // 2
  keypoints.emplace_back(cv::Point2f(600.f, 5.f), 7.f, -1.f, 1.f);    // 3
  keypoints.emplace_back(cv::Point2f(5.f, 470.f), 7.f, -1.f, 1.f);    // 4
  keypoints.emplace_back(cv::Point2f(320.f, 240.f), 7.f, -1.f, 1.f);  // 5
  const cv::Size image(640, 480);
  EXPECT_EQ(SpreadSubset(keypoints, image, 0).size(), keypoints.size());   // 0: all
  EXPECT_EQ(SpreadSubset(keypoints, image, 10).size(), keypoints.size());  // fewer than the cap
  EXPECT_EQ(SpreadSubset(keypoints, image, 4),
            (std::vector<int>{1, 3, 4, 5}));  // one per cell first
  EXPECT_EQ(SpreadSubset(keypoints, image, 5),
            (std::vector<int>{1, 2, 3, 4, 5}));                            // then the second best
  EXPECT_EQ(SpreadSubset(keypoints, image, 2), (std::vector<int>{1, 3}));  // first round, by index
}

}  // namespace
}  // namespace dynorb
