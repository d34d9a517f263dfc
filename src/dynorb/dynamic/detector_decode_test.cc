// Decoders, letterbox maths and NMS on constructed tensors (exact numbers).
#include "dynorb/dynamic/detector_decode.h"

#include <cmath>

#include <gtest/gtest.h>

namespace dynorb {
namespace {

TEST(DetectorDecode, LetterboxTopLeftAndCentred) {
  const ResizeTransform top = LetterboxTransform({640, 480}, {416, 416}, false);
  EXPECT_DOUBLE_EQ(top.scale_x, 0.65);
  EXPECT_EQ(top.resized_size, cv::Size(416, 312));
  EXPECT_EQ(top.pad_y, 0.0);
  const ResizeTransform mid = LetterboxTransform({640, 480}, {320, 320}, true);
  EXPECT_DOUBLE_EQ(mid.scale_x, 0.5);
  // A sliver keeps at least one row (0 rows would make cv::resize throw).
  const ResizeTransform sliver = LetterboxTransform({2000, 2}, {320, 320}, true);
  EXPECT_EQ(sliver.resized_size, cv::Size(320, 1));
  EXPECT_EQ(
      ApplyResize(cv::Mat(2, 2000, CV_8UC3, cv::Scalar(1, 2, 3)), sliver, cv::Scalar(114, 114, 114))
          .size(),
      cv::Size(320, 320));
  EXPECT_EQ(mid.pad_x, 0.0);
  EXPECT_EQ(mid.pad_y, 40.0);
  // A network box maps back through the pad and scale.
  Detection d;
  d.box = cv::Rect2f(10.f, 50.f, 100.f, 60.f);
  const auto img = MapToImage({d}, mid, {640, 480});
  ASSERT_EQ(img.size(), 1u);
  EXPECT_FLOAT_EQ(img[0].box.x, 20.f);
  EXPECT_FLOAT_EQ(img[0].box.y, 20.f);
  EXPECT_FLOAT_EQ(img[0].box.width, 200.f);
  EXPECT_FLOAT_EQ(img[0].box.height, 120.f);
  const cv::Mat padded = ApplyResize(cv::Mat(480, 640, CV_8UC3, cv::Scalar(1, 2, 3)), mid, cv::Scalar(114, 114, 114));
  EXPECT_EQ(padded.at<cv::Vec3b>(0, 0), cv::Vec3b(114, 114, 114));
  EXPECT_EQ(padded.at<cv::Vec3b>(160, 160), cv::Vec3b(1, 2, 3));
}

TEST(DetectorDecode, StretchMapsAxesIndependently) {
  const ResizeTransform t = StretchTransform({640, 480}, {320, 320});
  Detection d;
  d.box = cv::Rect2f(32.f, 32.f, 64.f, 64.f);
  const auto img = MapToImage({d}, t, {640, 480});
  EXPECT_FLOAT_EQ(img[0].box.x, 64.f);
  EXPECT_FLOAT_EQ(img[0].box.y, 48.f);
  EXPECT_FLOAT_EQ(img[0].box.height, 96.f);
}

TEST(DetectorDecode, DarknetRows) {
  cv::Mat rows = cv::Mat::zeros(2, 5 + 3, CV_32F);
  const float r0[] = {0.5f, 0.25f, 0.1f, 0.2f, 0.9f, 0.1f, 0.8f, 0.0f};
  std::copy(r0, r0 + 8, rows.ptr<float>(0));
  rows.at<float>(1, 5) = 0.1f;  // below threshold
  const auto d = DecodeDarknetRows(rows, {320, 320}, 0.3f);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].class_id, 1);
  EXPECT_FLOAT_EQ(d[0].score, 0.8f);
  EXPECT_FLOAT_EQ(d[0].box.x, 160.f - 16.f);
  EXPECT_FLOAT_EQ(d[0].box.y, 80.f - 32.f);
  EXPECT_FLOAT_EQ(d[0].box.width, 32.f);
}

// Only the allowed classes compete: a row whose best class is not allowed takes its best allowed
// class when that one passes the threshold, and is dropped otherwise.
TEST(DetectorDecode, OnlyAllowedClassesCompete) {
  cv::Mat rows = cv::Mat::zeros(2, 5 + 3, CV_32F);
  const float r0[] = {0.5f, 0.25f, 0.1f, 0.2f, 0.9f, 0.4f, 0.8f, 0.35f};
  const float r1[] = {0.5f, 0.25f, 0.1f, 0.2f, 0.9f, 0.1f, 0.8f, 0.2f};
  std::copy(r0, r0 + 8, rows.ptr<float>(0));
  std::copy(r1, r1 + 8, rows.ptr<float>(1));
  const auto all = DecodeDarknetRows(rows, {320, 320}, 0.3f);
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].class_id, 1);
  const auto d = DecodeDarknetRows(rows, {320, 320}, 0.3f, {true, false, true});
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].class_id, 0);
  EXPECT_FLOAT_EQ(d[0].score, 0.4f);
  EXPECT_TRUE(DecodeDarknetRows(rows, {320, 320}, 0.3f, {false, false, false}).empty());
}

TEST(DetectorDecode, YoloxGridOffsets) {
  const cv::Size net(64, 64);  // 8x8 + 4x4 + 2x2 = 84 anchors
  const int sizes[] = {1, 84, 7};
  cv::Mat out(3, sizes, CV_32F, cv::Scalar(0));
  // Anchor of stride 16 at grid (1, 2): index 64 + 2 * 4 + 1 = 73.
  float* row = out.ptr<float>() + 73 * 7;
  row[0] = 0.5f, row[1] = 0.25f, row[2] = std::log(2.f), row[3] = 0.f, row[4] = 0.8f, row[5] = 0.5f, row[6] = 0.9f;
  const auto d = DecodeYolox(out, net, 0.5f);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].class_id, 1);
  EXPECT_NEAR(d[0].score, 0.72f, 1e-6);
  EXPECT_NEAR(d[0].box.x + d[0].box.width / 2, (0.5f + 1) * 16, 1e-4);
  EXPECT_NEAR(d[0].box.y + d[0].box.height / 2, (0.25f + 2) * 16, 1e-4);
  EXPECT_NEAR(d[0].box.width, 32.f, 1e-4);
  EXPECT_NEAR(d[0].box.height, 16.f, 1e-4);
}

TEST(DetectorDecode, FastestDetCell) {
  const int sizes[] = {1, 7, 4, 4};
  cv::Mat out(4, sizes, CV_32F, cv::Scalar(0));
  auto at = [&](int c, int y, int x) -> float& { return out.ptr<float>()[(c * 4 + y) * 4 + x]; };
  at(0, 2, 1) = 0.81f;  // obj
  at(1, 2, 1) = 0.f;    // tanh(0) = 0
  at(2, 2, 1) = 0.f;
  at(3, 2, 1) = 0.f;  // sigmoid(0) = 0.5
  at(4, 2, 1) = 0.f;
  at(6, 2, 1) = 0.5f;  // class 1
  const auto d = DecodeFastestDet(out, {352, 352}, 0.3f);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].class_id, 1);
  EXPECT_NEAR(d[0].score, std::pow(0.81f, 0.6f) * std::pow(0.5f, 0.4f), 1e-6);
  EXPECT_NEAR(d[0].box.x + d[0].box.width / 2, 1.f / 4 * 352, 1e-3);
  EXPECT_NEAR(d[0].box.y + d[0].box.height / 2, 2.f / 4 * 352, 1e-3);
  EXPECT_NEAR(d[0].box.width, 176.f, 1e-3);
}

TEST(DetectorDecode, NanoDetDistributionIntegral) {
  // 16x16 input, stride 8 -> 2x2 cells, 2 classes, 4 bins.
  cv::Mat cls = cv::Mat::zeros(4, 2, CV_32F);
  cv::Mat reg(4, 16, CV_32F, cv::Scalar(-100.f));
  cls.at<float>(3, 0) = 0.7f;  // cell (1, 1)
  // left: all mass on bin 1 -> 8 px; top: bin 2 -> 16 px; right: uniform -> 1.5*8; bottom: bin 0.
  reg.at<float>(3, 1) = 0.f;
  reg.at<float>(3, 4 + 2) = 0.f;
  for (int b = 0; b < 4; ++b) reg.at<float>(3, 8 + b) = 0.f;
  reg.at<float>(3, 12) = 0.f;
  const auto d = DecodeNanoDetLevel(cls, reg, 8, {16, 16}, 0.5f);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_NEAR(d[0].box.x, 12.f - 8.f, 1e-4);
  EXPECT_NEAR(d[0].box.y, 12.f - 16.f, 1e-4);
  EXPECT_NEAR(d[0].box.width, 8.f + 12.f, 1e-4);
  EXPECT_NEAR(d[0].box.height, 16.f, 1e-4);
}

TEST(DetectorDecode, NmsIsClassWiseAndOrdered) {
  std::vector<Detection> in(4);
  in[0].box = {0, 0, 10, 10}, in[0].class_id = 0, in[0].score = 0.6f;
  in[1].box = {1, 0, 10, 10}, in[1].class_id = 0, in[1].score = 0.9f;  // suppresses 0
  in[2].box = {1, 0, 10, 10}, in[2].class_id = 1, in[2].score = 0.5f;  // other class: kept
  in[3].box = {50, 50, 10, 10}, in[3].class_id = 0, in[3].score = 0.7f;
  const auto out = NonMaxSuppression(in, 0.45f);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_FLOAT_EQ(out[0].score, 0.9f);
  EXPECT_FLOAT_EQ(out[1].score, 0.7f);
  EXPECT_EQ(out[2].class_id, 1);
  EXPECT_NEAR(BoxIou({0, 0, 10, 10}, {5, 0, 10, 10}), 50.f / 150.f, 1e-6);
}

}  // namespace
}  // namespace dynorb
