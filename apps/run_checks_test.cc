#include "run_checks.h"

#include <gtest/gtest.h>

namespace dynorb {
namespace {

cv::Mat Depth(float metres) { return cv::Mat(480, 640, CV_32FC1, cv::Scalar(metres)); }

FrameRecord Record(FrameId id, int used, int with_depth,
                   TrackingState state = TrackingState::kNotInitialized) {
  FrameRecord r;
  r.id = id;
  r.timestamp_s = 100.0 + id;
  r.num_keypoints = used;
  r.num_used = used;
  r.num_with_depth = with_depth;
  r.state = state;
  return r;
}

bool Mentions(const std::vector<std::string>& warnings, const std::string& text) {
  for (const std::string& w : warnings) {
    if (w.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(DepthScaleCheck, MedianOfTheFirstFramesValidDepths) {
  DepthScaleCheck check;
  cv::Mat half = Depth(2.0f);
  half.rowRange(0, 240).setTo(0.0f);    // No depth in the upper half: ignored.
  half.rowRange(400, 480).setTo(9.0f);  // A sixth of the valid pixels far away.
  check.Add(half);
  check.Add(Depth(0.0f));  // No depth at all: counted as seen only.
  check.Add(cv::Mat());
  EXPECT_EQ(check.frames_seen(), 3);
  EXPECT_EQ(check.frames_with_depth(), 1);
  EXPECT_DOUBLE_EQ(check.median_depth_m(), 2.0);
  for (int i = 0; i < 40; ++i) check.Add(Depth(7.0f));
  EXPECT_EQ(check.frames_seen(), DepthScaleCheck::kFramesChecked);
  EXPECT_EQ(check.frames_with_depth(), DepthScaleCheck::kFramesChecked - 2);
  EXPECT_DOUBLE_EQ(check.median_depth_m(), 7.0);
}

TEST(RunWarnings, NoneForAPlausibleInitialisedRun) {
  DepthScaleCheck check;
  for (int i = 0; i < 5; ++i) check.Add(Depth(2.5f));
  const std::vector<FrameRecord> records = {Record(0, 1000, 800, TrackingState::kOk)};
  EXPECT_TRUE(RunWarnings(check, records, RunCheckLimits()).empty());
}

TEST(RunWarnings, ADepthScaleOffByOrdersOfMagnitudeNamesDepthMapFactor) {
  // TUM depth (2.5 m = raw 12500) read with DepthMapFactor 1: 12500 m.
  DepthScaleCheck far;
  for (int i = 0; i < 5; ++i) far.Add(Depth(12500.0f));
  RunCheckLimits limits;
  limits.depth_map_factor = 1.0;
  const std::vector<FrameRecord> ok = {Record(0, 1000, 800, TrackingState::kOk)};
  std::vector<std::string> w = RunWarnings(far, ok, limits);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(Mentions(w, "1.25e+04 m away (median over the first 5 frames)")) << w[0];
  EXPECT_TRUE(Mentions(w, "check DepthMapFactor")) << w[0];
  EXPECT_TRUE(Mentions(w, "now 1)")) << w[0];
  DepthScaleCheck near;
  near.Add(Depth(0.0005f));  // Millimetre PNGs read with a factor of 5e6.
  EXPECT_TRUE(Mentions(RunWarnings(near, ok, RunCheckLimits()), "0.0005 m away"));
  DepthScaleCheck fine;
  fine.Add(Depth(12.0f));  // Far but possible.
  EXPECT_TRUE(RunWarnings(fine, ok, RunCheckLimits()).empty());
}

TEST(RunWarnings, NoDepthAtAllAndNeverInitialisedSayWhatToCheck) {
  DepthScaleCheck none;
  for (int i = 0; i < 3; ++i) none.Add(Depth(0.0f));
  const std::vector<FrameRecord> records = {Record(0, 1000, 0), Record(1, 1000, 0)};
  const std::vector<std::string> w = RunWarnings(none, records, RunCheckLimits());
  ASSERT_EQ(w.size(), 2u);
  EXPECT_TRUE(Mentions(w, "no valid depth (> 0) in the sampled pixels of the first 3 frames"))
      << w[0];
  EXPECT_TRUE(Mentions(
      w,
      "the map was never initialised: a frame needs at least 500 keypoints of which 100 with "
      "depth; the closest was frame 0 (t = 100.000000 s) with 1000 keypoints, 0 with depth; "
      "too little depth: check the depth images and DepthMapFactor"))
      << w[1];
}

TEST(RunWarnings, NeverInitialisedNamesTheFrameClosestToTheRule) {
  DepthScaleCheck check;
  check.Add(Depth(2.0f));
  // Frame 1 has plenty of depth but few keypoints (0.4 of the rule); frame 2 is short of both
  // by less (0.8 and 0.9): it is the closest. Frame 3 has no keypoints at all.
  const std::vector<FrameRecord> records = {Record(0, 100, 10), Record(1, 200, 200),
                                            Record(2, 400, 90), Record(3, 0, 0)};
  const std::vector<std::string> w = RunWarnings(check, records, RunCheckLimits());
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(
      Mentions(w, "the closest was frame 2 (t = 102.000000 s) with 400 keypoints, 90 with depth"))
      << w[0];
  // Once any frame initialised, no warning; an empty run has nothing to say either.
  std::vector<FrameRecord> later = records;
  later.push_back(Record(4, 900, 500, TrackingState::kOk));
  EXPECT_TRUE(RunWarnings(check, later, RunCheckLimits()).empty());
  EXPECT_TRUE(RunWarnings(DepthScaleCheck(), {}, RunCheckLimits()).empty());
}

TEST(RunWarnings, NeverInitialisedBecauseOfTheFilterSaysSoInDatasetFrameNumbers) {
  DepthScaleCheck check;
  check.Add(Depth(2.0f));
  FrameRecord r = Record(2, 300, 250);
  r.num_keypoints = 1000;  // The filter removed 700: what is left is below the rule.
  r.num_filtered = 700;
  RunCheckLimits limits;
  limits.first_frame = 100;  // --frames 100:...
  const std::vector<std::string> w = RunWarnings(check, {r}, limits);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(Mentions(w,
                       "the closest was frame 102 (t = 102.000000 s) with 300 keypoints, 250 with "
                       "depth; the keypoint filter removed 700 of its 1000 keypoints"))
      << w[0];
  EXPECT_FALSE(Mentions(w, "too few keypoints")) << w[0];
}

TEST(RunWarnings, NeverInitialisedOnAFrameTheFilterCouldNotJudgeBlamesNeitherDepthNorImages) {
  // `--mode fast` on a one-frame sequence: the first frame's keypoints are withheld.
  DepthScaleCheck check;
  check.Add(Depth(2.0f));
  FrameRecord r = Record(0, 0, 0);
  r.num_keypoints = 1013;
  r.num_filtered = 1013;
  r.judged = false;
  const std::vector<std::string> w = RunWarnings(check, {r}, RunCheckLimits());
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(Mentions(w,
                       "with 0 keypoints, 0 with depth; the keypoint filter withheld all 1013 of "
                       "its keypoints: it could not judge the frame"))
      << w[0];
  EXPECT_FALSE(Mentions(w, "too little depth")) << w[0];
  // A judged frame whose keypoints the filter removed: said as before, and no depth blame either
  // when too few keypoints were left to find depth on.
  r.judged = true;
  r.num_filtered = 1000;
  r.num_used = 13;
  r.num_with_depth = 5;
  const std::vector<std::string> judged = RunWarnings(check, {r}, RunCheckLimits());
  ASSERT_EQ(judged.size(), 1u);
  EXPECT_TRUE(Mentions(judged, "the keypoint filter removed 1000 of its 1013 keypoints"))
      << judged[0];
  EXPECT_FALSE(Mentions(judged, "too little depth")) << judged[0];
}

TEST(RunWarnings, TooFewKeypointsPointsAtTheImagesAndTheFeatureCount) {
  DepthScaleCheck check;
  check.Add(Depth(2.0f));
  const std::vector<std::string> w = RunWarnings(check, {Record(0, 300, 250)}, RunCheckLimits());
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(
      Mentions(w,
               "300 keypoints, 250 with depth; too few keypoints: blank or textureless images, or "
               "ORBextractor.nFeatures below 500"))
      << w[0];
  EXPECT_FALSE(Mentions(w, "too little depth")) << w[0];
  const std::vector<std::string> both = RunWarnings(check, {Record(0, 300, 20)}, RunCheckLimits());
  ASSERT_EQ(both.size(), 1u);
  EXPECT_TRUE(Mentions(both, "too few keypoints")) << both[0];
  EXPECT_TRUE(Mentions(both, "too little depth")) << both[0];
}

}  // namespace
}  // namespace dynorb
