// Where the carried suspect map lands when the camera moves a lot between an analysed frame and
// the carried one (`fast.analyse_every` 2). A constructed scene: a textured wall 4 m away and a
// textured box 2 m away, both facing the camera, which translates along x (so every image is the
// two textures shifted by whole pixels: exact images and depths). The box moves down between
// frames 1 and 2 (the analysed frame 2 finds it) and stands still while the camera jumps 0.3 m
// before the carried frame 3: the box's image moves 80 px, the wall's 40 px. The carried mask must
// land on the box where the camera's motion puts it, not where it was (a carry that ignores the
// motion) nor on the other side (one that applies it the wrong way round).
// The same scene with the box standing still, then moving, tests the quiet schedule
// (`fast.quiet_analyse_every`).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "dynorb/core/error.h"
#include "dynorb/dynamic/fast_clip_test_util.h"
#include "dynorb/dynamic/fast_filter.h"
#include "dynorb/dynamic/fast_test_util.h"
#include "dynorb/features/orb_extractor.h"

namespace dynorb {
namespace {

constexpr double kWallDepthM = 4.0, kBoxDepthM = 2.0;
constexpr int kBoxPx = 160;

// A blob texture: uniform noise at 1/8 resolution, upsampled (corners at every scale).
cv::Mat BlobTexture(cv::Size size, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat low(size.height / 8 + 1, size.width / 8 + 1, CV_8U);
  rng.fill(low, cv::RNG::UNIFORM, 0, 256);
  cv::Mat texture;
  cv::resize(low, texture, cv::Size(low.cols * 8, low.rows * 8), 0, 0, cv::INTER_CUBIC);
  return texture(cv::Rect(cv::Point(), size)).clone();
}

// The camera moved so far along x that the wall's image shifted camera_wall_px to the left; the
// box's top-left corner at (box_x_px, box_y_px) in the image of a camera at x = 0. The frame's
// mask is the box (255).
ClipFrame RenderWallAndBox(int camera_wall_px, int box_x_px, int box_y_px) {
  static const cv::Mat wall = BlobTexture(cv::Size(1200, 600), 3);
  static const cv::Mat box = BlobTexture(cv::Size(kBoxPx, kBoxPx), 4);
  const PinholeCamera camera = FastTestCamera();
  ClipFrame f;
  // The wall's image shifts by camera_wall_px; the box's (half as far) by twice that.
  f.world_from_cam = Rigid3d(Eigen::Quaterniond::Identity(),
                             Eigen::Vector3d(camera_wall_px * kWallDepthM / camera.fx, 0.0, 0.0));
  f.gray = wall(cv::Rect(200 + camera_wall_px, 60, camera.width, camera.height)).clone();
  f.depth_m = cv::Mat(f.gray.size(), CV_32F, cv::Scalar(kWallDepthM));
  f.mask = cv::Mat::zeros(f.gray.size(), CV_8U);
  const cv::Rect at(box_x_px - 2 * camera_wall_px, box_y_px, kBoxPx, kBoxPx);
  const cv::Rect visible = at & cv::Rect(cv::Point(), f.gray.size());
  box(visible - at.tl()).copyTo(f.gray(visible));
  f.depth_m(visible).setTo(kBoxDepthM);
  f.mask(visible).setTo(255);
  cv::cvtColor(f.gray, f.bgr, cv::COLOR_GRAY2BGR);
  return f;
}

// cam_from_previous_cam of frame i (the camera translates along x only).
Rigid3d CameraMotion(const std::vector<ClipFrame>& frames, size_t i) {
  return frames[i].world_from_cam.Inverse() * frames[i - 1].world_from_cam;
}

// The keypoints on the box (mask != 0), how many of them the filter removed, and how many it
// removed off the box.
struct BoxCount {
  int keypoints = 0, removed = 0, removed_off = 0;
};
BoxCount CountOnBox(const KeypointSet& set, const cv::Mat& mask, const FilterOutput& out) {
  BoxCount c;
  for (size_t k = 0; k < set.keypoints.size(); ++k) {
    const bool on_box = mask.at<uint8_t>(KeypointPixel(set.keypoints[k], mask.size())) != 0;
    c.keypoints += on_box;
    c.removed += on_box && !out.keep[k];
    c.removed_off += !on_box && !out.keep[k];
  }
  return c;
}

class CarryUnderLargeMotion : public ::testing::Test {
 protected:
  struct Carried {
    double recall = 0.0;       // box keypoints removed in the carried frame
    double mask_on_box = 0.0;  // fraction of the carried mask's pixels on the box
    double box_in_mask = 0.0;  // fraction of the box's pixels in the carried mask
    int box_keypoints = 0, removed_off_box = 0;
  };

  // Frames 0-2 analysed / carried / analysed with the exact motion; frame 3 carried with
  // `frame3_prediction` as the tracker's cam_from_previous_cam.
  static Carried Run(const std::vector<ClipFrame>& frames, const Rigid3d& frame3_prediction) {
    FastOptions options;
    options.analyse_every = 2;
    FastFilter filter(options, FastTestCamera());
    const OrbExtractor extractor;
    Carried result;
    for (size_t i = 0; i < frames.size(); ++i) {
      const ClipFrame& f = frames[i];
      const KeypointSet set = extractor.Detect(f.gray);
      FilterInput input = ClipInput(f, set, i);
      if (i > 0) input.predicted_cam_from_previous_cam = CameraMotion(frames, i);
      if (i == 3) input.predicted_cam_from_previous_cam = frame3_prediction;
      const FilterOutput out = filter.Filter(input);
      if (i == 2) {
        EXPECT_GT(filter.info().num_removed, 20) << "the analysed frame finds the box";
      }
      if (i != 3) continue;
      const BoxCount box = CountOnBox(set, f.mask, out);
      result.box_keypoints = box.keypoints;
      result.removed_off_box = box.removed_off;
      result.recall = static_cast<double>(box.removed) / std::max(1, box.keypoints);
      if (out.dynamic_mask.empty()) continue;
      const double on_box = cv::countNonZero(out.dynamic_mask & f.mask);
      result.mask_on_box = on_box / std::max(1, cv::countNonZero(out.dynamic_mask));
      result.box_in_mask = on_box / cv::countNonZero(f.mask);
    }
    return result;
  }
};

TEST_F(CarryUnderLargeMotion, TheMaskLandsWhereTheCameraMotionPutsTheObject) {
  // Wall shifts 0, 4, 8 px, then 40 px more; the box moves 0, 0, 26 px down, then stands still.
  const std::vector<ClipFrame> frames = {
      RenderWallAndBox(0, 300, 100), RenderWallAndBox(4, 300, 100), RenderWallAndBox(8, 300, 126),
      RenderWallAndBox(48, 300, 126)};
  const Rigid3d exact = CameraMotion(frames, 3);
  const Carried right = Run(frames, exact);
  const Carried still = Run(frames, Rigid3d());
  const Carried backwards = Run(frames, exact.Inverse());
  for (const auto& [name, c] : {std::pair{"exact", right}, std::pair{"identity", still},
                                std::pair{"inverted", backwards}}) {
    std::printf(
        "%-8s carried frame: box keypoints %d, removed %.3f, removed off the box %d; mask on the "
        "box %.3f, box in the mask %.3f\n",
        name, c.box_keypoints, c.recall, c.removed_off_box, c.mask_on_box, c.box_in_mask);
  }
  ASSERT_GT(right.box_keypoints, 40);
  EXPECT_GE(right.recall, 0.9);
  EXPECT_GE(right.box_in_mask, 0.8);
  EXPECT_GE(right.mask_on_box, 0.6);  // the rest: the dilation around the box's outline
  for (const Carried* wrong : {&still, &backwards}) {
    EXPECT_LT(wrong->recall, right.recall - 0.3);
    EXPECT_LT(wrong->box_in_mask, right.box_in_mask - 0.3);
  }
}

// The quiet schedule (FastOptions::quiet_*): the camera translates along x, the box stands still
// for frames 0-7 (a quiet scene), then moves down 6 px per frame. What the filter does per frame.
struct QuietFrame {
  bool analysed = false;  // the cues ran (false: carried)
  int tracked = 0, retracked = 0, removed = 0, box_keypoints = 0, box_removed = 0;
};

// wall_px: the camera's position per frame (the wall's image shift, px); empty: 4 px per frame.
std::vector<QuietFrame> RunQuietScene(const FastOptions& options, int frames,
                                      const std::vector<int>& wall_px = {}) {
  FastFilter filter(options, FastTestCamera());
  const OrbExtractor extractor;
  std::vector<QuietFrame> result;
  std::vector<ClipFrame> clip;
  constexpr int kStill = 8;
  for (int i = 0; i < frames; ++i) {
    const int camera_px = wall_px.empty() ? 4 * i : wall_px[i];
    clip.push_back(RenderWallAndBox(camera_px, 300, 100 + 6 * std::max(0, i - kStill + 1)));
  }
  for (size_t i = 0; i < clip.size(); ++i) {
    const ClipFrame& f = clip[i];
    const KeypointSet set = extractor.Detect(f.gray);
    FilterInput input = ClipInput(f, set, i);
    if (i > 0) input.predicted_cam_from_previous_cam = CameraMotion(clip, i);
    const FilterOutput out = filter.Filter(input);
    QuietFrame q;
    q.analysed = filter.info().has_previous;
    q.tracked = filter.info().num_tracked;
    q.retracked = filter.info().num_retracked;
    q.removed = filter.info().num_removed;
    const BoxCount box = CountOnBox(set, f.mask, out);
    q.box_keypoints = box.keypoints;
    q.box_removed = box.removed;
    result.push_back(q);
  }
  return result;
}

// FastOptions' default is off (1); `dynorb run --mode fast` sets 2 (apps/mode_fast.cc).
TEST(FastQuietSchedule, OffByDefaultEveryFrameAnalysedWithAllItsPoints) {
  const std::vector<QuietFrame> frames = RunQuietScene(FastOptions(), 12);
  for (size_t i = 1; i < frames.size(); ++i) {
    EXPECT_TRUE(frames[i].analysed) << i;
    EXPECT_GT(frames[i].tracked, 300) << i;
  }
}

TEST(FastQuietSchedule, EveryThirdFrameCarriedWhileQuietEveryFrameOnceTheBoxMoves) {
  FastOptions options;
  options.quiet_analyse_every = 2;
  const std::vector<QuietFrame> frames = RunQuietScene(options, 14);
  // Two quiet analyses in a row, then one carried frame: 1, 2 analysed, 3 carried, 4, 5
  // analysed, 6 carried, 7 analysed.
  for (int i : {1, 2, 4, 5, 7}) EXPECT_TRUE(frames[i].analysed) << i;
  for (int i : {3, 6}) EXPECT_FALSE(frames[i].analysed) << i;
  // The box moves from frame 8 on (analysed: 7 was the first after a carry); every frame after
  // is analysed.
  for (int i = 8; i < 14; ++i) {
    EXPECT_TRUE(frames[i].analysed) << i;
    ASSERT_GT(frames[i].box_keypoints, 40) << i;
    EXPECT_GE(static_cast<double>(frames[i].box_removed) / frames[i].box_keypoints, 0.8) << i;
  }
}

TEST(FastQuietSchedule, OnlyWithFlowAndRegionsElseEveryFrameAnalysed) {
  // A carried frame needs flow (its LK pyramid) and the suspect map: without them the schedule
  // is ignored, not an error (fast mode's default schedule must not reject descriptors).
  for (const bool descriptors : {true, false}) {
    FastOptions options;
    options.quiet_analyse_every = 2;
    if (descriptors) {
      options.correspondences = "descriptors";
    } else {
      options.use_region = false;
    }
    const std::vector<QuietFrame> frames = RunQuietScene(options, 8);
    for (size_t i = 1; i < frames.size(); ++i) EXPECT_TRUE(frames[i].analysed) << i;
  }
  FastOptions options;
  options.quiet_min_analyses = 0;
  EXPECT_THROW(options.Validate(), InputError);
  options = FastOptions();
  options.quiet_analyse_every = 9;
  EXPECT_THROW(options.Validate(), InputError);
}

// Parallax is not motion: the standing box, twice as near as the wall, has twice the wall's flow,
// so the magnitude cue calls it moving (here weighted to make a seed on its own); the warp
// residual with each point's own depth calls it static. With residual_static_veto the
// frame-pair cues do not count there and the box is kept (`dynorb run --mode fast` sets it).
TEST(FastResidualVeto, ANearStandingObjectsLargerFlowMakesNoSeed) {
  FastOptions options;
  options.weight_magnitude = 1.0;
  FastOptions veto = options;
  veto.residual_static_veto = true;
  const std::vector<QuietFrame> without = RunQuietScene(options, 7);
  const std::vector<QuietFrame> with = RunQuietScene(veto, 7);
  int removed_without = 0;
  for (int i = 1; i < 7; ++i) {
    ASSERT_GT(with[i].box_keypoints, 40) << i;
    removed_without += without[i].box_removed;
    // At most a lone corner on its outline (where the wall slides behind the box's edge).
    EXPECT_LE(with[i].box_removed, 2) << i;
    EXPECT_LE(with[i].removed, 5) << i;
    std::printf("frame %d box keypoints %d removed without the veto %d, with %d\n", i,
                with[i].box_keypoints, without[i].box_removed, with[i].box_removed);
  }
  EXPECT_GT(removed_without, 100);
}

// The camera speeds up (4, then 6, then 9 px per frame on the wall) while the box stands: the
// LK guesses of frame 2 and of frame 4 (the analysis after the carried frame 3) come from the
// previous, slower motion. By default only frame 4 removes the shared offset of its guesses
// before the retrack test; lk_base_shift_always does it on frame 2 too.
TEST(FastQuietSchedule, TheAnalysisAfterACarryRemovesItsGuessesSharedError) {
  const std::vector<int> wall_px = {0, 4, 10, 16, 25, 34, 43, 52};
  FastOptions off;
  off.quiet_analyse_every = 2;
  off.lk_base_shift_min_points = 0;
  FastOptions after_carry = off;
  after_carry.lk_base_shift_min_points = FastOptions().lk_base_shift_min_points;
  FastOptions always = after_carry;
  always.lk_base_shift_always = true;
  const int n = static_cast<int>(wall_px.size());
  const std::vector<QuietFrame> a = RunQuietScene(off, n, wall_px);
  const std::vector<QuietFrame> b = RunQuietScene(after_carry, n, wall_px);
  const std::vector<QuietFrame> c = RunQuietScene(always, n, wall_px);
  for (const std::vector<QuietFrame>* run : {&a, &b, &c}) {
    for (int i : {1, 2, 4, 5, 7}) EXPECT_TRUE((*run)[i].analysed) << i;
    for (int i : {3, 6}) EXPECT_FALSE((*run)[i].analysed) << i;
  }
  // Frame 2: a guess 2 px off on the wall, 4 px on the box; only lk_base_shift_always shifts.
  EXPECT_GT(a[2].retracked, 0.9 * a[2].tracked);
  EXPECT_EQ(b[2].retracked, a[2].retracked);
  EXPECT_LT(c[2].retracked, 0.3 * c[2].tracked);
  // Frame 4, after the carry: 3 px off on the wall; shifted by default, only the box's points
  // (a fifth of them) are tracked again.
  EXPECT_GT(a[4].retracked, 0.9 * a[4].tracked);
  EXPECT_LT(b[4].retracked, 0.3 * b[4].tracked);
  EXPECT_LT(c[4].retracked, 0.3 * c[4].tracked);
  // The same tracks found, and the standing box kept.
  for (int i = 1; i < n; ++i) {
    EXPECT_NEAR(b[i].tracked, a[i].tracked, 5) << i;
    EXPECT_LE(b[i].removed, 5) << i;
    EXPECT_EQ(b[i].box_removed, 0) << i;
  }
  FastOptions bad;
  bad.lk_base_shift_min_points = -1;
  EXPECT_THROW(bad.Validate(), InputError);
}

}  // namespace
}  // namespace dynorb
