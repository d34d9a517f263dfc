#include "dynorb/dynamic/combined_filter.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace dynorb {
namespace {

// Rejects keypoints whose x lies in [x0, x1); draws a filled square at (x0, 0) on its overlay.
class BandFilter : public KeypointFilter {
 public:
  BandFilter(float x0, float x1, double ms) : x0_(x0), x1_(x1), ms_(ms) {}
  std::string name() const override { return "band"; }
  FilterOutput Filter(const FilterInput& input) override {
    ++calls;
    FilterOutput out;
    for (const cv::KeyPoint& k : input.keypoints->keypoints)
      out.keep.push_back(!(k.pt.x >= x0_ && k.pt.x < x1_));
    out.dynamic_mask = cv::Mat::zeros(input.gray->size(), CV_8U);
    out.dynamic_mask.colRange(static_cast<int>(x0_), static_cast<int>(x1_)).setTo(255);
    out.judged = judged;
    if (input.want_overlay) {
      out.overlay = input.bgr->clone();
      cv::rectangle(out.overlay, cv::Rect(static_cast<int>(x0_), 0, 4, 4), cv::Scalar(0, 0, 255),
                    cv::FILLED);
    }
    return out;
  }
  std::vector<std::pair<std::string, double>> StageTimings() const override {
    return {{"work", ms_}};
  }
  int calls = 0;
  bool judged = true;

 private:
  float x0_, x1_;
  double ms_;
};

struct Frame {
  cv::Mat bgr = cv::Mat(20, 40, CV_8UC3, cv::Scalar(50, 60, 70));
  cv::Mat gray = cv::Mat(20, 40, CV_8UC1, cv::Scalar(60));
  KeypointSet keypoints;
  FilterInput Input(bool overlay) {
    for (float x : {2.f, 12.f, 22.f, 32.f})
      keypoints.keypoints.emplace_back(cv::Point2f(x, 5.f), 7.f);
    FilterInput in;
    in.bgr = &bgr;
    in.gray = &gray;
    in.keypoints = &keypoints;
    in.want_overlay = overlay;
    return in;
  }
};

TEST(CombinedFilter, KeepsOnlyWhatEveryPartKeepsAndOrsTheMasks) {
  std::vector<CombinedFilter::Part> parts;
  parts.push_back({"semantic", std::make_unique<BandFilter>(10.f, 20.f, 3.0)});
  parts.push_back({"fast", std::make_unique<BandFilter>(30.f, 40.f, 1.5)});
  CombinedFilter combined(std::move(parts));
  Frame frame;
  const FilterOutput out = combined.Filter(frame.Input(true));
  EXPECT_EQ(out.keep, (std::vector<bool>{true, false, true, false}));
  EXPECT_EQ(cv::countNonZero(out.dynamic_mask), 20 * 20);
  // Both drawings survive in the composed overlay; untouched pixels are the frame's.
  EXPECT_EQ(out.overlay.at<cv::Vec3b>(1, 11), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(out.overlay.at<cv::Vec3b>(1, 31), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(out.overlay.at<cv::Vec3b>(10, 5), cv::Vec3b(50, 60, 70));

  const auto stages = combined.StageTimings();
  ASSERT_EQ(stages.size(), 4u);
  EXPECT_EQ(stages[0].first, "semantic");
  EXPECT_EQ(stages[1], (std::pair<std::string, double>{"semantic.work", 3.0}));
  EXPECT_EQ(stages[2].first, "fast");
  EXPECT_EQ(stages[3], (std::pair<std::string, double>{"fast.work", 1.5}));
  EXPECT_NE(combined.name().find("band + band"), std::string::npos);
}

TEST(CombinedFilter, JudgedWhenAnyPartJudged) {
  for (const bool second_judged : {false, true}) {
    std::vector<CombinedFilter::Part> parts;
    auto a = std::make_unique<BandFilter>(10.f, 20.f, 1.0);
    auto b = std::make_unique<BandFilter>(30.f, 40.f, 1.0);
    a->judged = false;
    b->judged = second_judged;
    parts.push_back({"a", std::move(a)});
    parts.push_back({"b", std::move(b)});
    CombinedFilter combined(std::move(parts));
    Frame frame;
    EXPECT_EQ(combined.Filter(frame.Input(false)).judged, second_judged);
  }
}

TEST(CombinedFilter, OnlyInsideMaskDropsRemovalsOutsideThePartsRegion) {
  // The part rejects x in [10, 40) but its mask marks only [10, 20): the keypoints at 22 and 32
  // are isolated votes and are kept.
  class WideVotes : public BandFilter {
   public:
    WideVotes() : BandFilter(10.f, 20.f, 0.0) {}
    FilterOutput Filter(const FilterInput& input) override {
      FilterOutput out = BandFilter::Filter(input);
      for (size_t i = 0; i < out.keep.size(); ++i) out.keep[i] = input.keypoints->keypoints[i].pt.x < 10.f;
      return out;
    }
  };
  std::vector<CombinedFilter::Part> parts;
  parts.push_back({"fast", std::make_unique<WideVotes>(), true});
  CombinedFilter combined(std::move(parts));
  Frame frame;
  EXPECT_EQ(combined.Filter(frame.Input(false)).keep, (std::vector<bool>{true, false, true, true}));
}

TEST(CombinedFilter, APartThatWouldRemoveTooMuchIsDistrustedForTheFrame) {
  // "semantic" removes x in [10, 20) (1 of 4 keypoints); "fast" then removes x in [0, 40): all
  // 3 keypoints semantic kept, above its cap of 1/2, so its removals and mask are dropped.
  auto make = [](double cap) {
    std::vector<CombinedFilter::Part> parts;
    parts.push_back({"semantic", std::make_unique<BandFilter>(10.f, 20.f, 0.0)});
    parts.push_back({"fast", std::make_unique<BandFilter>(0.f, 40.f, 0.0), true, cap});
    return CombinedFilter(std::move(parts));
  };
  CombinedFilter capped = make(0.5);
  Frame frame;
  const FilterOutput out = capped.Filter(frame.Input(false));
  EXPECT_EQ(out.keep, (std::vector<bool>{true, false, true, true}));
  EXPECT_EQ(cv::countNonZero(out.dynamic_mask), 10 * 20);
  EXPECT_EQ(capped.distrusted_frames(1), 1);
  EXPECT_EQ(capped.distrusted_frames(0), 0);
  CombinedFilter uncapped = make(1.0);
  Frame frame2;
  EXPECT_EQ(uncapped.Filter(frame2.Input(false)).keep, (std::vector<bool>(4, false)));
  EXPECT_EQ(uncapped.distrusted_frames(1), 0);
  std::vector<CombinedFilter::Part> bad;
  bad.push_back({"fast", std::make_unique<BandFilter>(0.f, 5.f, 0.0), true, 0.0});
  EXPECT_THROW(CombinedFilter(std::move(bad)), std::invalid_argument);
}

TEST(CombinedFilter, RegionsMostlyInsideTheEarlierMaskAreLeftToIt) {
  // "fast" has two regions: x in [8, 24) (10 of its 16 columns inside semantic's [10, 20)) and
  // x in [30, 36) (outside), and votes on the keypoints at x = 12, 22, 32.
  class TwoRegions : public BandFilter {
   public:
    TwoRegions() : BandFilter(0.f, 0.f, 0.0) {}
    FilterOutput Filter(const FilterInput& input) override {
      FilterOutput out;
      for (const cv::KeyPoint& k : input.keypoints->keypoints) out.keep.push_back(k.pt.x < 10.f);
      out.dynamic_mask = cv::Mat::zeros(input.gray->size(), CV_8U);
      out.dynamic_mask.colRange(8, 24).setTo(255);
      out.dynamic_mask.colRange(30, 36).setTo(255);
      return out;
    }
  };
  auto make = [](double max_overlap) {
    std::vector<CombinedFilter::Part> parts;
    parts.push_back({"semantic", std::make_unique<BandFilter>(10.f, 20.f, 0.0)});
    parts.push_back({"fast", std::make_unique<TwoRegions>(), true, 1.0, max_overlap});
    return CombinedFilter(std::move(parts));
  };
  for (const double max_overlap : {1.0, 0.7, 0.5, 0.0}) {
    SCOPED_TRACE(max_overlap);
    CombinedFilter combined = make(max_overlap);
    Frame frame;
    const FilterOutput out = combined.Filter(frame.Input(false));
    const bool left_to_semantic = max_overlap < 10.0 / 16.0;
    EXPECT_EQ(out.keep, (std::vector<bool>{true, false, left_to_semantic, false}));
    // Semantic's band plus fast's outside region, plus fast's overlapping one unless dropped.
    EXPECT_EQ(cv::countNonZero(out.dynamic_mask), 20 * (10 + 6 + (left_to_semantic ? 0 : 6)));
  }
  const cv::Mat earlier = cv::Mat::zeros(4, 8, CV_8U);
  cv::Mat mask = cv::Mat::zeros(4, 8, CV_8U);
  mask.at<uint8_t>(1, 1) = 255;
  EXPECT_EQ(cv::countNonZero(CombinedFilter::RegionsMostlyOutside(mask, cv::Mat(), 0.0)), 1);  // No earlier mask.
  EXPECT_EQ(cv::countNonZero(CombinedFilter::RegionsMostlyOutside(mask, earlier, 0.0)), 1);
  std::vector<CombinedFilter::Part> bad;
  bad.push_back({"fast", std::make_unique<BandFilter>(0.f, 5.f, 0.0), true, 1.0, 1.5});
  EXPECT_THROW(CombinedFilter(std::move(bad)), std::invalid_argument);
}

TEST(CombinedFilter, AllowsARefillOnlyWhenEveryPartsRemovalsAreCoveredByItsMask) {
  class Covering : public BandFilter {
   public:
    Covering() : BandFilter(10.f, 20.f, 0.0) {}
    bool MaskCoversDetections() const override { return true; }
  };
  auto make = [](bool allow, bool fast_only_inside) {
    std::vector<CombinedFilter::Part> parts;
    parts.push_back({"semantic", std::make_unique<Covering>()});
    parts.push_back({"fast", std::make_unique<BandFilter>(30.f, 40.f, 0.0), fast_only_inside});
    return CombinedFilter(std::move(parts), allow);
  };
  EXPECT_FALSE(make(false, true).MaskCoversDetections());  // Not asked for.
  EXPECT_TRUE(make(true, true).MaskCoversDetections());
  EXPECT_FALSE(make(true, false).MaskCoversDetections());  // Isolated FAST votes outside its mask.
}

TEST(CombinedFilter, NoOverlayUnlessAskedAndEmptyPartsRejected) {
  std::vector<CombinedFilter::Part> parts;
  parts.push_back({"a", std::make_unique<BandFilter>(0.f, 5.f, 0.0)});
  CombinedFilter combined(std::move(parts));
  Frame frame;
  EXPECT_TRUE(combined.Filter(frame.Input(false)).overlay.empty());
  EXPECT_THROW(CombinedFilter(std::vector<CombinedFilter::Part>{}), std::invalid_argument);
}

}  // namespace
}  // namespace dynorb
