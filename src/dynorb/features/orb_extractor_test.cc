#include "dynorb/features/orb_extractor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <set>
#include <thread>

#include "dynorb/core/error.h"
#include "dynorb/features/brief_pattern.h"
#include "dynorb/features/orb_descriptor.h"
#include "dynorb/features/synthetic_texture.h"

namespace dynorb {
namespace {

const cv::Size kVga(640, 480);

TEST(OrbOptions, DefaultsAndValidation) {
  const OrbOptions o;
  EXPECT_EQ(o.n_features, 1000);
  EXPECT_DOUBLE_EQ(o.scale_factor, 1.2);
  EXPECT_EQ(o.n_levels, 8);
  EXPECT_EQ(o.ini_th_fast, 20);
  EXPECT_EQ(o.min_th_fast, 7);
  EXPECT_NO_THROW(o.Validate());
  auto bad = [](auto mutate) {
    OrbOptions b;
    mutate(b);
    EXPECT_THROW(b.Validate(), InputError);
    EXPECT_THROW(OrbExtractor{b}, InputError);
  };
  bad([](OrbOptions& b) { b.n_features = 0; });
  bad([](OrbOptions& b) { b.scale_factor = 1.0; });
  // Session 55: levels of one size (1.0001: every keypoint found on each of them), and budgets
  // whose sum overflowed an int.
  bad([](OrbOptions& b) { b.scale_factor = 1.0001; });
  bad([](OrbOptions& b) { b.n_features = 2147483647; });
  OrbOptions edge;
  edge.scale_factor = kMinOrbScaleFactor;
  edge.n_features = kMaxOrbFeatures;
  edge.n_levels = 32;
  EXPECT_NO_THROW(OrbExtractor{edge});
  bad([](OrbOptions& b) { b.n_levels = 0; });
  bad([](OrbOptions& b) { b.ini_th_fast = 0; });
  bad([](OrbOptions& b) { b.min_th_fast = 21; });
  bad([](OrbOptions& b) { b.cell_size_px = 2; });
}

TEST(OrbExtractor, ScaleTablesAndLevelBudgets) {
  const OrbExtractor extractor;
  const ScaleLevels& s = extractor.levels();
  ASSERT_EQ(s.NumLevels(), 8);
  for (int l = 0; l < 8; ++l) {
    EXPECT_NEAR(s.scale[l], std::pow(1.2, l), 1e-12);
    EXPECT_NEAR(s.sigma2[l], std::pow(1.44, l), 1e-12);
    EXPECT_NEAR(s.inv_sigma2[l] * s.sigma2[l], 1.0, 1e-12);
    EXPECT_NEAR(s.inv_scale[l] * s.scale[l], 1.0, 1e-12);
  }
  const std::vector<int>& budget = extractor.features_per_level();
  EXPECT_EQ(std::accumulate(budget.begin(), budget.end(), 0), 1000);
  EXPECT_EQ(budget[0], 217);  // 1000·(1 − 1/1.2)/(1 − 1.2^-8) = 216.8
  for (int l = 1; l + 1 < 8; ++l) EXPECT_NEAR(budget[l], budget[l - 1] / 1.2, 1.0);
}

TEST(OrbExtractor, RejectsBadImages) {
  const OrbExtractor extractor;
  EXPECT_THROW(extractor.Detect(cv::Mat()), InputError);
  EXPECT_THROW(extractor.Detect(cv::Mat(kVga, CV_8UC3, cv::Scalar::all(0))), InputError);
  EXPECT_THROW(extractor.Detect(cv::Mat(kVga, CV_16UC1, cv::Scalar::all(0))), InputError);
  // Too small for any level: no keypoints, no crash; a blank image has none either.
  EXPECT_EQ(extractor.Detect(cv::Mat(30, 30, CV_8UC1, cv::Scalar(0))).size(), 0);
  EXPECT_EQ(extractor.Detect(cv::Mat(kVga, CV_8UC1, cv::Scalar(128))).size(), 0);
  const KeypointSet small = extractor.Detect(MakeSyntheticTexture(cv::Size(90, 70), 3));
  EXPECT_GT(small.size(), 0);
  EXPECT_EQ(extractor.Describe(small).rows, small.size());
}

TEST(OrbExtractor, CountCloseToBudgetAndCoordinatesConsistent) {
  const OrbExtractor extractor;
  const cv::Mat image = MakeSyntheticTexture(kVga, 1);
  const KeypointSet set = extractor.Detect(image);
  EXPECT_GE(set.size(), 950);
  EXPECT_LE(set.size(), 1000 + 3 * 8);
  ASSERT_EQ(set.level_pixels.size(), set.keypoints.size());
  std::vector<int> per_level(8, 0);
  for (int i = 0; i < set.size(); ++i) {
    const cv::KeyPoint& kp = set.keypoints[i];
    ASSERT_GE(kp.octave, 0);
    ASSERT_LT(kp.octave, 8);
    ++per_level[kp.octave];
    const double s = extractor.levels().scale[kp.octave];
    // Inside the image, and at least ≈ kEdgeThreshold level pixels from every border.
    const double margin = kEdgeThreshold * s - s;
    EXPECT_GE(kp.pt.x, margin);
    EXPECT_GE(kp.pt.y, margin);
    EXPECT_LE(kp.pt.x, image.cols - 1 - margin);
    EXPECT_LE(kp.pt.y, image.rows - 1 - margin);
    EXPECT_FLOAT_EQ(kp.size, static_cast<float>(kPatchSize * s));
    EXPECT_GE(kp.angle, 0.f);
    EXPECT_LT(kp.angle, 360.f);
    // The full-resolution position is the exact image of the level pixel.
    const cv::Point px = set.level_pixels[i];
    const cv::Size level_size = set.pyramid->Level(kp.octave).size();
    EXPECT_NEAR(kp.pt.x, (px.x + 0.5) * image.cols / level_size.width - 0.5, 1e-3);
    EXPECT_NEAR(kp.pt.y, (px.y + 0.5) * image.rows / level_size.height - 0.5, 1e-3);
    const cv::Point2f back = set.pyramid->FullToLevel(kp.octave, kp.pt);
    EXPECT_NEAR(back.x, px.x, 1e-3);
    EXPECT_NEAR(back.y, px.y, 1e-3);
  }
  for (int l = 0; l < 8; ++l) {
    EXPECT_GE(per_level[l], extractor.features_per_level()[l] * 9 / 10) << "level " << l;
    EXPECT_LE(per_level[l], extractor.features_per_level()[l] + 3) << "level " << l;
  }
}

TEST(OrbExtractor, DistributionCoversTheImage) {
  const OrbExtractor extractor;
  const KeypointSet set = extractor.Detect(MakeSyntheticTexture(kVga, 2));
  std::set<int> cells;
  for (const cv::KeyPoint& kp : set.keypoints) {
    cells.insert(static_cast<int>(kp.pt.y / 80) * 8 + static_cast<int>(kp.pt.x / 80));
  }
  EXPECT_GE(cells.size(), 0.8 * 48);
  // Level 0 alone covers it too (its keypoints lie ≥ 19 px inside).
  std::set<int> cells0;
  for (const cv::KeyPoint& kp : set.keypoints) {
    if (kp.octave == 0)
      cells0.insert(static_cast<int>(kp.pt.y / 80) * 8 + static_cast<int>(kp.pt.x / 80));
  }
  EXPECT_GE(cells0.size(), 0.8 * 48);
}

TEST(OrbExtractor, FallbackThresholdFindsWeakCorners) {
  // Low-contrast squares (contrast 12 < ini_th_fast = 20 but > min_th_fast = 7): only the
  // fallback threshold can find their corners.
  cv::Mat image(kVga, CV_8UC1, cv::Scalar(100));
  for (int y = 40; y < 440; y += 60) {
    for (int x = 40; x < 600; x += 60)
      cv::rectangle(image, {x, y}, {x + 20, y + 20}, cv::Scalar(112), cv::FILLED);
  }
  OrbOptions strict;
  strict.min_th_fast = strict.ini_th_fast;
  EXPECT_EQ(OrbExtractor(strict).Detect(image).size(), 0);
  EXPECT_GT(OrbExtractor().Detect(image).size(), 100);
}

TEST(OrbExtractor, KnownCornerFoundAtEveryLevelWithoutBias) {
  // A bright, slightly blurred square centred in the image, corners at the pixel edges 159.5 /
  // 479.5 and 119.5 / 359.5. Every level must find each corner within ≈ 1.5 level pixels (FAST
  // fires just inside the corner), and by symmetry the four offsets must cancel: a wrong
  // level → full-resolution convention (e.g. x_0 = s·x_l) would leave a mean offset ≈ (s − 1)/2.
  cv::Mat image(kVga, CV_8UC1, cv::Scalar(40));
  cv::rectangle(image, {160, 120}, {479, 359}, cv::Scalar(210), cv::FILLED);
  cv::GaussianBlur(image, image, cv::Size(5, 5), 1.0);
  OrbOptions options;
  options.n_features = 20000;
  const OrbExtractor extractor(options);
  const KeypointSet set = extractor.Detect(image);
  const cv::Point2f corners[4] = {
      {159.5f, 119.5f}, {479.5f, 119.5f}, {159.5f, 359.5f}, {479.5f, 359.5f}};
  for (int l = 0; l < 8; ++l) {
    const double s = extractor.levels().scale[l];
    cv::Point2f offset_sum(0, 0);
    for (const cv::Point2f& c : corners) {
      double best = 1e9;
      cv::Point2f best_offset;
      for (const cv::KeyPoint& kp : set.keypoints) {
        if (kp.octave == l && cv::norm(kp.pt - c) < best) {
          best = cv::norm(kp.pt - c);
          best_offset = kp.pt - c;
        }
      }
      EXPECT_LE(best, 1.5 * s + 1.5) << "level " << l << " corner " << c;
      offset_sum += best_offset;
    }
    EXPECT_LT(std::abs(offset_sum.x / 4), 0.1 * s) << "level " << l;
    EXPECT_LT(std::abs(offset_sum.y / 4), 0.1 * s) << "level " << l;
  }
}

TEST(OrbExtractor, DescribeAfterFilterEqualsDescribeAllThenSelect) {
  const OrbExtractor extractor;
  const KeypointSet set = extractor.Detect(MakeSyntheticTexture(kVga, 4));
  const cv::Mat all = extractor.Describe(set);
  ASSERT_EQ(all.rows, set.size());
  ASSERT_EQ(all.cols, kBriefBytes);
  ASSERT_EQ(all.type(), CV_8UC1);
  std::vector<bool> keep(set.size());
  for (int i = 0; i < set.size(); ++i) keep[i] = (i * 7919) % 3 != 0;
  const OrbFeatures kept = extractor.DescribeKept(set, keep);
  int row = 0;
  for (int i = 0; i < set.size(); ++i) {
    if (!keep[i]) continue;
    ASSERT_LT(row, kept.descriptors.rows);
    EXPECT_EQ(kept.keypoints[row].pt, set.keypoints[i].pt);
    EXPECT_EQ(cv::norm(kept.descriptors.row(row), all.row(i), cv::NORM_HAMMING), 0.0);
    ++row;
  }
  EXPECT_EQ(row, kept.descriptors.rows);
  // Index form, reversed order, and a single high-level keypoint alone (lazy per-level blur).
  std::vector<int> reversed(set.size());
  std::iota(reversed.rbegin(), reversed.rend(), 0);
  const cv::Mat rev = extractor.Describe(set, reversed);
  for (int i = 0; i < set.size(); ++i) {
    EXPECT_EQ(cv::norm(rev.row(set.size() - 1 - i), all.row(i), cv::NORM_HAMMING), 0.0);
  }
  const int last = set.size() - 1;
  EXPECT_EQ(cv::norm(extractor.Describe(set, {last}), all.row(last), cv::NORM_HAMMING), 0.0);
  EXPECT_EQ(extractor.Describe(set, {}).rows, 0);
}

TEST(OrbExtractor, DetectExcludingSpendsTheBudgetOutsideTheMask) {
  const OrbExtractor extractor;
  const KeypointSet all = extractor.Detect(MakeSyntheticTexture(kVga, 9));
  // An empty exclusion changes nothing.
  const KeypointSet same = extractor.DetectExcluding(all, cv::Mat::zeros(kVga, CV_8U));
  ASSERT_EQ(same.size(), all.size());
  for (int i = 0; i < all.size(); ++i) EXPECT_EQ(same.keypoints[i].pt, all.keypoints[i].pt) << i;
  // Exclude the left 40 % (as a person covering part of the view).
  cv::Mat exclude = cv::Mat::zeros(kVga, CV_8U);
  const int boundary = kVga.width * 2 / 5;
  exclude.colRange(0, boundary).setTo(255);
  const KeypointSet right = extractor.DetectExcluding(all, exclude);
  EXPECT_EQ(right.pyramid, all.pyramid);  // Same pyramid, no second build.
  OrbOptions two_levels;
  two_levels.n_levels = 2;  // A pyramid of 8 levels read with 2 levels' tables (an ASan overflow).
  EXPECT_THROW(OrbExtractor(two_levels).DetectExcluding(all, exclude), InputError);
  int inside = 0, kept_right = 0;
  for (const cv::KeyPoint& kp : right.keypoints) inside += kp.pt.x < boundary - 1.f ? 1 : 0;
  for (const cv::KeyPoint& kp : all.keypoints) kept_right += kp.pt.x >= boundary ? 1 : 0;
  EXPECT_EQ(inside, 0);
  // The whole budget goes to the rest: about as many keypoints as before, far more than the
  // ones the first detection had there.
  EXPECT_GE(right.size(), all.size() * 9 / 10);
  EXPECT_GT(right.size(), kept_right * 5 / 4);
  // Angles reused from the first detection or computed now: each is the keypoint's own
  // intensity-centroid angle on its level.
  ASSERT_EQ(right.level_pixels.size(), right.keypoints.size());
  int reused = 0;
  for (int i = 0; i < right.size(); ++i) {
    const cv::KeyPoint& kp = right.keypoints[i];
    EXPECT_EQ(kp.angle,
              IntensityCentroidAngleDeg(right.pyramid->Level(kp.octave), right.level_pixels[i]))
        << i;
    for (int j = 0; j < all.size(); ++j) {
      if (all.keypoints[j].octave == kp.octave && all.level_pixels[j] == right.level_pixels[i]) {
        ++reused;
        break;
      }
    }
  }
  EXPECT_GT(reused, kept_right / 2);  // the case the reuse serves exists in this test
  EXPECT_THROW(extractor.DetectExcluding(all, cv::Mat::zeros(10, 10, CV_8U)), InputError);
}

TEST(OrbExtractor, DeterministicAndIndependentOfTheCallersBuffer) {
  cv::Mat image = MakeSyntheticTexture(kVga, 5);
  const OrbFeatures a = OrbExtractor().DetectAndDescribe(image);
  const KeypointSet set = OrbExtractor().Detect(image);
  image.setTo(cv::Scalar(0));  // the set keeps its own copy of the pyramid
  const cv::Mat b = OrbExtractor().Describe(set);
  ASSERT_EQ(a.keypoints.size(), set.keypoints.size());
  for (size_t i = 0; i < a.keypoints.size(); ++i) {
    EXPECT_EQ(a.keypoints[i].pt, set.keypoints[i].pt);
    EXPECT_EQ(a.keypoints[i].angle, set.keypoints[i].angle);
    EXPECT_EQ(a.keypoints[i].octave, set.keypoints[i].octave);
    EXPECT_EQ(a.keypoints[i].response, set.keypoints[i].response);
  }
  EXPECT_EQ(cv::norm(a.descriptors, b, cv::NORM_HAMMING), 0.0);
}

TEST(OrbExtractor, ConcurrentCallsOnOneExtractorMatchSerial) {
  const OrbExtractor extractor;
  const cv::Mat images[2] = {MakeSyntheticTexture(kVga, 7), MakeSyntheticTexture(kVga, 8)};
  OrbFeatures serial[2], parallel[2];
  for (int i = 0; i < 2; ++i) serial[i] = extractor.DetectAndDescribe(images[i]);
  std::thread t0([&] { parallel[0] = extractor.DetectAndDescribe(images[0]); });
  std::thread t1([&] { parallel[1] = extractor.DetectAndDescribe(images[1]); });
  t0.join();
  t1.join();
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(serial[i].keypoints.size(), parallel[i].keypoints.size());
    EXPECT_EQ(cv::norm(serial[i].descriptors, parallel[i].descriptors, cv::NORM_HAMMING), 0.0);
  }
}

TEST(OrbExtractor, DescriptorBitsAreBalancedAndDistinct) {
  const OrbExtractor extractor;
  const OrbFeatures f = extractor.DetectAndDescribe(MakeSyntheticTexture(kVga, 6));
  ASSERT_GT(f.descriptors.rows, 500);
  int extreme_bits = 0;
  for (int bit = 0; bit < kBriefBits; ++bit) {
    int ones = 0;
    for (int r = 0; r < f.descriptors.rows; ++r)
      ones += (f.descriptors.at<uint8_t>(r, bit / 8) >> (bit % 8)) & 1;
    const double p = static_cast<double>(ones) / f.descriptors.rows;
    if (p < 0.2 || p > 0.8) ++extreme_bits;
  }
  EXPECT_LE(extreme_bits, kBriefBits / 20);
  double sum = 0;
  int n = 0;
  for (int r = 0; r + 1 < f.descriptors.rows; r += 2, ++n) {
    sum += cv::norm(f.descriptors.row(r), f.descriptors.row(r + 1), cv::NORM_HAMMING);
  }
  EXPECT_GT(sum / n, 115.0);  // unrelated keypoints: ≈ 128 for ideal independent bits
}

}  // namespace
}  // namespace dynorb
