// Box -> mask refinement with depth (mask_refine.h): the foreground cluster inside a box, boxes
// beyond the image, depth that is no measurement.
#include "dynorb/dynamic/mask_refine.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace dynorb {
namespace {

TEST(MaskRefine, PersonBoxOverFarWallKeepsTheWall) {
  cv::Mat depth(120, 160, CV_32F, cv::Scalar(4.0f));  // wall at 4 m
  depth(cv::Rect(60, 20, 40, 100)) = 1.5f;            // person at 1.5 m
  depth(cv::Rect(70, 30, 3, 3)) = 0.f;                // a hole in the person's depth
  cv::Mat mask = cv::Mat::zeros(depth.size(), CV_8U);
  DepthRefineOptions options;
  options.dilation_px = 2;
  const RefinedMask r = AddRefinedBoxMask({40, 10, 80, 110}, depth, options, 0.f, &mask);
  EXPECT_TRUE(r.refined);
  EXPECT_NEAR(r.depth_m, 1.5f, 1e-6);
  EXPECT_EQ(mask.at<uint8_t>(60, 80), 255);  // person
  EXPECT_EQ(mask.at<uint8_t>(31, 71), 255);  // hole closed
  EXPECT_EQ(mask.at<uint8_t>(60, 58), 255);  // within the dilation
  EXPECT_EQ(mask.at<uint8_t>(60, 45), 0);    // wall inside the box survives
  EXPECT_EQ(mask.at<uint8_t>(15, 80), 0);
  EXPECT_EQ(cv::countNonZero(mask(cv::Rect(0, 0, 30, 120))), 0);
  // Without refinement the whole box is masked.
  cv::Mat box_mask = cv::Mat::zeros(depth.size(), CV_8U);
  options.enabled = false;
  AddRefinedBoxMask({40, 10, 80, 110}, depth, options, 0.f, &box_mask);
  EXPECT_EQ(box_mask.at<uint8_t>(60, 45), 255);
}

// Depth a caller converted badly (inf, or beyond any sensor's range) is no measurement: before
// session 54 an inf or a 3e8 m pixel in the box's centre wrote far outside a histogram (a crash).
TEST(MaskRefine, InfiniteOrAbsurdDepthIsNoMeasurement) {
  DepthRefineOptions options;
  options.dilation_px = 0;
  const cv::Rect2f box(16.f, 12.f, 32.f, 24.f);
  cv::Mat reference_depth(48, 64, CV_32F, cv::Scalar(5.0f));
  reference_depth(cv::Rect(24, 18, 16, 12)) = 2.0f;  // a near object in the box's centre
  cv::Mat reference = cv::Mat::zeros(reference_depth.size(), CV_8U);
  AddRefinedBoxMask(box, reference_depth, options, 0.f, &reference);
  ASSERT_GT(cv::countNonZero(reference), 0);
  for (float bad : {std::numeric_limits<float>::infinity(), 3e8f, 1e30f}) {
    SCOPED_TRACE(bad);
    cv::Mat depth = reference_depth.clone();
    depth.at<float>(24, 32) = bad;  // one pixel in the centre
    cv::Mat mask = cv::Mat::zeros(depth.size(), CV_8U);
    AddRefinedBoxMask(box, depth, options, 0.f, &mask);
    EXPECT_LE(cv::countNonZero(mask != reference), 1);  // at most the bad pixel itself
  }
  // No finite depth at all: the whole box is masked, as for a box without depth.
  cv::Mat mask = cv::Mat::zeros(reference_depth.size(), CV_8U);
  AddRefinedBoxMask(box,
                    cv::Mat(48, 64, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity())),
                    options, 0.f, &mask);
  EXPECT_EQ(cv::countNonZero(mask), 32 * 24);
}

// Boxes from a file may lie anywhere: far outside the image, larger than an int, NaN.
TEST(MaskRefine, BoxesBeyondTheImageAreClipped) {
  const cv::Mat depth(48, 64, CV_32F, cv::Scalar(2.0f));
  DepthRefineOptions options;
  options.dilation_px = 0;
  cv::Mat mask = cv::Mat::zeros(depth.size(), CV_8U);
  AddRefinedBoxMask({-1e12f, -1e12f, 3e12f, 3e12f}, depth, options, 0.f, &mask);
  EXPECT_EQ(cv::countNonZero(mask), 48 * 64);  // covers the whole image
  mask.setTo(0);
  AddRefinedBoxMask({1e12f, 5.f, 1e12f, 1e26f}, depth, options, 0.f, &mask);
  AddRefinedBoxMask({-50.f, -50.f, 10.f, 10.f}, depth, options, 0.f, &mask);
  AddRefinedBoxMask({std::nanf(""), 5.f, 10.f, 10.f}, depth, options, 0.f, &mask);
  EXPECT_EQ(cv::countNonZero(mask), 0);
  AddRefinedBoxMask({60.5f, 40.5f, 1e9f, 1e9f}, depth, options, 0.f, &mask);
  EXPECT_EQ(cv::countNonZero(mask), 4 * 8);  // columns 60-63, rows 40-47
}

}  // namespace
}  // namespace dynorb
