// The FAST mode's regions on constructed data: the upsampled and dilated region mask, region
// growing on a constructed depth map, the suspect map carried over frames and camera motion.
#include "dynorb/dynamic/fast_region.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/dynamic/fast_cues.h"

namespace dynorb {
namespace {

// The windowed upsampling + dilation equals upsampling and dilating the whole image.
TEST(UpsampleAndDilate, SameAsWholeImageUpsampleAndDilate) {
  cv::RNG rng(5);
  for (int trial = 0; trial < 40; ++trial) {
    const int scale = trial % 2 ? 4 : 3, radius = trial % 7;
    const cv::Size full(641 - trial % 3, 479 + trial % 2);  // not always a multiple of the scale
    const cv::Size low((full.width + scale - 1) / scale, (full.height + scale - 1) / scale);
    cv::Mat low_mask = cv::Mat::zeros(low, CV_8U);
    for (int blob = 0; blob < trial % 4; ++blob) {  // 0-3 blobs, some at the image border
      const cv::Point c(rng.uniform(0, low.width), rng.uniform(0, low.height));
      cv::ellipse(low_mask, c, cv::Size(rng.uniform(1, 20), rng.uniform(1, 30)), 0, 0, 360, cv::Scalar(255), cv::FILLED);
    }
    cv::Mat expected;
    cv::resize(low_mask, expected, cv::Size(low.width * scale, low.height * scale), 0, 0, cv::INTER_NEAREST);
    expected = expected(cv::Rect(0, 0, full.width, full.height)).clone();
    if (radius > 0) {
      cv::dilate(expected, expected, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1)));
    }
    const cv::Mat got = UpsampleAndDilate(low_mask, scale, full, radius);
    ASSERT_EQ(got.size(), full);
    EXPECT_EQ(cv::countNonZero(got != expected), 0) << "trial " << trial;
  }
}

// Background at 3 m, a "person" (box) at 1.5 m standing on nothing; seeds grow to the whole box.
TEST(MaskWithinRadius, EuclideanDistanceToTheNearestSetPixel) {
  cv::Mat mask = cv::Mat::zeros(40, 50, CV_8U);
  mask.at<uint8_t>(10, 10) = 255;  // (x 10, y 10)
  EXPECT_TRUE(MaskWithinRadius(mask, {10.f, 10.f}, 0.f));
  EXPECT_FALSE(MaskWithinRadius(mask, {11.f, 10.f}, 0.f));
  EXPECT_TRUE(MaskWithinRadius(mask, {13.f, 14.f}, 5.f));  // distance 5 exactly
  EXPECT_FALSE(MaskWithinRadius(mask, {13.f, 14.f}, 4.9f));
  EXPECT_FALSE(MaskWithinRadius(mask, {14.f, 14.f}, 5.5f));  // a 5 px square is not a disc: 5.66
  EXPECT_TRUE(MaskWithinRadius(mask, {13.4f, 13.6f}, 5.f));  // rounded to the pixel (13, 14)
  // Near and beyond the border: only pixels inside the image count, nothing is read outside.
  mask.at<uint8_t>(0, 49) = 255;
  EXPECT_TRUE(MaskWithinRadius(mask, {52.f, -2.f}, 3.7f));
  EXPECT_FALSE(MaskWithinRadius(mask, {52.f, -2.f}, 3.5f));
  EXPECT_FALSE(MaskWithinRadius(cv::Mat::zeros(40, 50, CV_8U), {20.f, 20.f}, 30.f));
}

TEST(GrowRegions, SeedsGrowToTheDepthSegment) {
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(3.f));
  const cv::Rect person(200, 100, 120, 300);
  depth(person).setTo(1.5f);
  depth(cv::Rect(250, 150, 4, 4)).setTo(0.f);  // a hole
  const RegionOptions options;
  const cv::Mat low = DownsampleDepth(depth, options.scale, options.max_depth_m);
  const std::vector<RegionPoint> seeds = {{{230.f, 150.f}, 1.5f, {3.f, 0.f}}, {{280.f, 300.f}, 1.5f, {3.f, 1.f}}};
  const std::vector<RegionPoint> statics = {{{100.f, 100.f}, 0.f, {}}, {{500.f, 400.f}, 0.f, {}}};
  const RegionResult r = GrowRegions(low, depth.size(), seeds, statics, cv::Mat(), options);
  ASSERT_EQ(r.num_accepted, 1);
  int inside = 0, outside = 0;
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      if (!r.mask.at<uint8_t>(y, x)) continue;
      (person.contains({x, y}) ? inside : outside)++;
    }
  }
  EXPECT_GT(inside, 0.97 * person.area());
  EXPECT_LT(outside, 2 * options.dilate_px * (person.width + person.height) + 1000);
  // One seed is not enough; a region full of static points is rejected.
  EXPECT_EQ(GrowRegions(low, depth.size(), {seeds[0]}, statics, cv::Mat(), options).num_accepted, 0);
  std::vector<RegionPoint> many_static;
  for (int i = 0; i < 30; ++i) many_static.push_back({{210.f + 3 * i, 200.f}, 0.f, {}});
  // Seeds moving in opposite directions are noise, not a mover.
  const std::vector<RegionPoint> incoherent = {{{230.f, 150.f}, 1.5f, {3.f, 0.f}}, {{280.f, 300.f}, 1.5f, {-3.f, 0.f}}};
  EXPECT_EQ(GrowRegions(low, depth.size(), incoherent, statics, cv::Mat(), options).num_accepted, 0);
  EXPECT_EQ(GrowRegions(low, depth.size(), seeds, many_static, cv::Mat(), options).num_accepted, 0);
  // A single seed is enough where the suspect map says something moved recently.
  cv::Mat suspect = cv::Mat::zeros(low.size(), CV_8U);
  suspect(cv::Rect(50, 25, 30, 75)).setTo(255);
  EXPECT_EQ(GrowRegions(low, depth.size(), {seeds[0]}, statics, suspect, options).num_accepted, 1);
}

// A mover that touches all four image borders is grown to exactly its low-resolution pixels
// (the flood fill reaches the first and last rows and columns and never wraps from one row's end
// to the next row's start); a depth map that is a view into a larger one gives the same result.
TEST(GrowRegions, ReachesEveryBorderAndAcceptsAView) {
  RegionOptions options;
  options.max_area = 1.0;
  cv::Mat big(140, 180, CV_32F, cv::Scalar(3.f));
  const cv::Rect view(10, 10, 160, 120);
  cv::Mat low = big(view);
  ASSERT_FALSE(low.isContinuous());
  low(cv::Rect(0, 50, 160, 20)).setTo(1.5f);  // a band from the left to the right border
  low(cv::Rect(70, 0, 20, 120)).setTo(1.5f);  // and from the top to the bottom border
  low(cv::Rect(159, 29, 1, 21)).setTo(1.5f);  // the last column up from the band to row 29
  low(cv::Rect(0, 69, 1, 23)).setTo(1.5f);    // the first column down from the band to row 91
  // Row 30's first pixel follows row 29's last one in memory, and row 90's last pixel precedes
  // row 91's first one, but both are cut off from the band.
  low.at<float>(30, 0) = 1.5f;
  low.at<float>(90, 159) = 1.5f;
  const cv::Size full(640, 480);
  const std::vector<RegionPoint> seeds = {{{320.f, 240.f}, 1.5f, {2.f, 0.f}},
                                          {{330.f, 250.f}, 1.5f, {2.f, 0.f}}};
  const RegionResult from_view = GrowRegions(low, full, seeds, {}, cv::Mat(), options);
  ASSERT_EQ(from_view.num_regions, 1);
  ASSERT_EQ(from_view.num_accepted, 1);
  cv::Mat expected = low == 1.5f;
  expected.at<uint8_t>(30, 0) = expected.at<uint8_t>(90, 159) = 0;
  EXPECT_EQ(cv::countNonZero(from_view.low_mask != expected), 0);
  const RegionResult from_copy = GrowRegions(low.clone(), full, seeds, {}, cv::Mat(), options);
  EXPECT_EQ(cv::countNonZero(from_copy.low_mask != from_view.low_mask), 0);
  EXPECT_EQ(cv::countNonZero(from_copy.mask != from_view.mask), 0);
}
TEST(Suspect, PropagatesWhereDepthMatchesAndExpires) {
  const PinholeCamera camera = TumFreiburg3Camera();
  const int s = 4;
  cv::Mat low(120, 160, CV_32F, cv::Scalar(2.f));
  cv::Mat mask = cv::Mat::zeros(low.size(), CV_8U);
  mask(cv::Rect(40, 40, 20, 20)).setTo(255);
  SuspectMap map;
  AddToSuspect(mask, low, &map);
  SuspectMap next = PropagateSuspect(map, low, camera, s, Rigid3d(), 3, 0.2);
  EXPECT_EQ(cv::countNonZero(next.Suspect(3)), 400);
  // The mover left: the background behind (4 m) is not suspect.
  cv::Mat revealed(low.size(), CV_32F, cv::Scalar(4.f));
  EXPECT_EQ(cv::countNonZero(PropagateSuspect(map, revealed, camera, s, Rigid3d(), 3, 0.2).Suspect(3)), 0);
  for (int i = 0; i < 3; ++i) next = PropagateSuspect(next, low, camera, s, Rigid3d(), 3, 0.2);
  EXPECT_EQ(cv::countNonZero(next.Suspect(3)), 0);
}

// Under a real camera motion the suspect map follows the scene: every current pixel takes the
// age + 1 of the previous pixel its point lands on (WarpToPrevious, nearest low-resolution pixel)
// where the depths agree, and its own depth. Random depths and ages against that rule applied
// pixel by pixel; pixels whose landing point lies within 1e-3 px of a rounding boundary are not
// compared (the two computations round differently in the last bits).
TEST(Suspect, FollowsTheCameraMotionPixelByPixel) {
  const PinholeCamera camera = TumFreiburg3Camera();
  const int s = 4, max_age = 3;
  const double tol = 0.2;
  cv::RNG rng(15);
  cv::Mat low(120, 160, CV_32F);
  rng.fill(low, cv::RNG::UNIFORM, 1.0, 4.0);
  low(cv::Rect(0, 0, 160, 10)).setTo(0.f);  // no depth: never suspect
  SuspectMap previous;
  previous.age = cv::Mat(low.size(), CV_8U);
  rng.fill(previous.age, cv::RNG::UNIFORM, 0, 6);
  previous.depth = cv::Mat(low.size(), CV_32F);
  // Random previous depths: most disagree with the points landing there.
  rng.fill(previous.depth, cv::RNG::UNIFORM, 0.5, 5.0);
  Rigid3d prev_from_cur(
      Eigen::AngleAxisd(0.03, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix(),
      Eigen::Vector3d(0.04, -0.02, 0.03));
  // Where the point of current pixel (x, y) lands: the previous low-resolution pixel, its depth
  // there; *clear: not near a rounding boundary.
  auto land = [&](int x, int y, long* px, long* py, double* z_prev, bool* clear) {
    const float z = low.at<float>(y, x);
    if (z <= 0.f) return false;
    const cv::Point2f u =
        WarpToPrevious(camera, prev_from_cur, cv::Point2f(x * s + s / 2, y * s + s / 2), z, z_prev);
    const float lx = (u.x + 0.5f) / s - 0.5f, ly = (u.y + 0.5f) / s - 0.5f;
    *px = std::lround(lx);
    *py = std::lround(ly);
    *clear = std::abs(lx - std::floor(lx) - 0.5f) > 1e-3f &&
             std::abs(ly - std::floor(ly) - 0.5f) > 1e-3f;
    return *px >= 0 && *py >= 0 && *px < low.cols && *py < low.rows;
  };
  long px = 0, py = 0;
  double z_prev = 0.0;
  bool clear = true;
  // Make half of the landing pixels agree in depth.
  for (int y = 0; y < low.rows; ++y) {
    for (int x = 0; x < low.cols; ++x) {
      if ((x + y) % 2 == 0 && land(x, y, &px, &py, &z_prev, &clear)) {
        previous.depth.at<float>(py, px) =
            static_cast<float>(z_prev + 0.1 * rng.uniform(-1.0, 1.0));
      }
    }
  }
  // The rule, pixel by pixel: the expected age and depth of every clear pixel.
  auto check = [&](const SuspectMap& next, int min_carried, int min_behind) {
    int carried = 0, behind = 0, compared = 0;
    for (int y = 0; y < low.rows; ++y) {
      for (int x = 0; x < low.cols; ++x) {
        int age = 255;
        float depth = 0.f;
        clear = true;
        if (land(x, y, &px, &py, &z_prev, &clear)) {
          const int before = previous.age.at<uint8_t>(py, px);
          if (before < max_age && std::abs(previous.depth.at<float>(py, px) - z_prev) <= tol) {
            age = before + 1;
            depth = low.at<float>(y, x);
          }
        }
        behind += low.at<float>(y, x) > 0.f && z_prev <= 1e-6;
        if (!clear) continue;
        ++compared;
        carried += age != 255;
        EXPECT_EQ(next.age.at<uint8_t>(y, x), age) << x << "," << y;
        EXPECT_EQ(next.depth.at<float>(y, x), depth) << x << "," << y;
      }
    }
    EXPECT_GT(compared, static_cast<int>(low.total()) * 9 / 10);
    EXPECT_GE(carried, min_carried);
    EXPECT_GE(behind, min_behind);
  };
  check(PropagateSuspect(previous, low, camera, s, prev_from_cur, max_age, tol), 1000, 0);
  // The camera moved 2.5 m forward: the nearer points are behind it, nothing lands from them.
  const Rigid3d moved_forward = prev_from_cur;
  prev_from_cur = Rigid3d(moved_forward.rotation, Eigen::Vector3d(0.0, 0.0, -2.5));
  check(PropagateSuspect(previous, low, camera, s, prev_from_cur, max_age, tol), 10, 1000);
  prev_from_cur = moved_forward;
  // Everything in the previous map one frame from expiring: still carried over (once more) ...
  SuspectMap old;
  old.age = cv::Mat(low.size(), CV_8U, cv::Scalar(max_age - 1));
  old.depth = previous.depth.clone();
  std::swap(old, previous);
  check(PropagateSuspect(previous, low, camera, s, prev_from_cur, max_age, tol), 1000, 0);
  // ... and nothing once every pixel is too old.
  previous.age.setTo(max_age);
  EXPECT_EQ(
      cv::countNonZero(
          PropagateSuspect(previous, low, camera, s, prev_from_cur, max_age, tol).Suspect(max_age)),
      0);
}

}  // namespace
}  // namespace dynorb
