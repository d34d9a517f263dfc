// Where the carried suspect map lands when the camera moves a lot between an analysed frame and
// the carried one (`fast.analyse_every` 2). A constructed scene: a textured wall 4 m away and a
// textured box 2 m away, both facing the camera, which translates along x (so every image is the
// two textures shifted by whole pixels: exact images and depths). The box moves down between
// frames 1 and 2 (the analysed frame 2 finds it) and stands still while the camera jumps 0.3 m
// before the carried frame 3: the box's image moves 80 px, the wall's 40 px. The carried mask must
// land on the box where the camera's motion puts it, not where it was (a carry that ignores the
// motion) nor on the other side (one that applies it the wrong way round).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include <opencv2/imgproc.hpp>

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

class CarryUnderLargeMotion : public ::testing::Test {
 protected:
  // The camera moved so far along x that the wall's image shifted camera_wall_px to the left; the
  // box's top-left corner at (box_x_px, box_y_px) in the image of a camera at x = 0. The frame's
  // mask is the box (255).
  static ClipFrame Render(int camera_wall_px, int box_x_px, int box_y_px) {
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
  static Rigid3d Motion(const std::vector<ClipFrame>& frames, size_t i) {
    return frames[i].world_from_cam.Inverse() * frames[i - 1].world_from_cam;
  }

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
      if (i > 0) input.predicted_cam_from_previous_cam = Motion(frames, i);
      if (i == 3) input.predicted_cam_from_previous_cam = frame3_prediction;
      const FilterOutput out = filter.Filter(input);
      if (i == 2) {
        EXPECT_GT(filter.info().num_removed, 20) << "the analysed frame finds the box";
      }
      if (i != 3) continue;
      int removed_on_box = 0;
      for (size_t k = 0; k < set.keypoints.size(); ++k) {
        const bool on_box = f.mask.at<uint8_t>(KeypointPixel(set.keypoints[k], f.mask.size())) != 0;
        result.box_keypoints += on_box;
        removed_on_box += on_box && !out.keep[k];
        result.removed_off_box += !on_box && !out.keep[k];
      }
      result.recall = static_cast<double>(removed_on_box) / std::max(1, result.box_keypoints);
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
  const std::vector<ClipFrame> frames = {Render(0, 300, 100), Render(4, 300, 100),
                                         Render(8, 300, 126), Render(48, 300, 126)};
  const Rigid3d exact = Motion(frames, 3);
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

}  // namespace
}  // namespace dynorb
