#include "dynorb/dynamic/morphology.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace dynorb {
namespace {

cv::Mat Element(int radius_px) {
  return cv::getStructuringElement(cv::MORPH_ELLIPSE,
                                   cv::Size(2 * radius_px + 1, 2 * radius_px + 1));
}

// Sparse binary masks (what the filters dilate) and full-range grey images.
cv::Mat RandomImage(cv::Size size, bool binary, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat image(size, CV_8U);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  if (binary) image = image > 245;
  return image;
}

bool Equal(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::countNonZero(a != b) == 0;
}

TEST(MorphologyTest, EllipseOperationsEqualOpenCvPixelForPixel) {
  const cv::Size sizes[] = {{1, 1}, {40, 3}, {3, 40}, {37, 53}, {120, 90}};
  int cases = 0;
  for (const cv::Size size : sizes) {
    for (int radius = 0; radius <= 12; ++radius) {
      for (bool binary : {true, false}) {
        const cv::Mat src = RandomImage(size, binary, 1000 * size.width + 10 * radius + binary);
        cv::Mat expected, got;
        cv::dilate(src, expected, Element(radius));
        DilateEllipse(src, radius, &got);
        ASSERT_TRUE(Equal(expected, got)) << "dilate " << size << " r " << radius;
        cv::erode(src, expected, Element(radius));
        ErodeEllipse(src, radius, &got);
        ASSERT_TRUE(Equal(expected, got)) << "erode " << size << " r " << radius;
        cv::morphologyEx(src, expected, cv::MORPH_CLOSE, Element(radius));
        CloseEllipse(src, radius, &got);
        ASSERT_TRUE(Equal(expected, got)) << "close " << size << " r " << radius;
        ++cases;
      }
    }
  }
  EXPECT_EQ(cases, 5 * 13 * 2);
}

TEST(MorphologyTest, ReadsAnRoiAsAnIsolatedImageAndMayWriteInPlace) {
  const cv::Mat parent = RandomImage({200, 150}, true, 7);
  const cv::Rect window(30, 20, 90, 70);
  cv::Mat expected, got;
  cv::dilate(parent(window), expected, Element(8), cv::Point(-1, -1), 1,
             cv::BORDER_CONSTANT | cv::BORDER_ISOLATED, cv::Scalar(0));
  DilateEllipse(parent(window), 8, &got);
  EXPECT_TRUE(Equal(expected, got));
  // Pixels of the parent just outside the window would change the result if they were read.
  cv::Mat reference;
  cv::dilate(parent(window), reference, Element(8));
  EXPECT_FALSE(Equal(expected, reference));

  cv::Mat in_place = parent.clone();
  cv::dilate(parent, expected, Element(5));
  DilateEllipse(in_place, 5, &in_place);
  EXPECT_TRUE(Equal(expected, in_place));
}

TEST(MorphologyTest, ASinglePixelGrowsIntoTheEllipse) {
  cv::Mat src = cv::Mat::zeros(21, 21, CV_8U);
  src.at<uint8_t>(10, 10) = 255;
  cv::Mat got;
  DilateEllipse(src, 8, &got);
  EXPECT_TRUE(Equal(got(cv::Rect(2, 2, 17, 17)), Element(8) * 255));
  EXPECT_EQ(cv::countNonZero(got), cv::countNonZero(Element(8)));
  EXPECT_THROW(DilateEllipse(cv::Mat(5, 5, CV_32F), 2, &got), cv::Exception);
}

}  // namespace
}  // namespace dynorb
