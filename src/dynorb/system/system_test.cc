#include "dynorb/system/system.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <opencv2/imgproc.hpp>

#include "dynorb/core/error.h"
#include "dynorb/features/synthetic_texture.h"
#include "dynorb/tracking/test_world.h"

namespace dynorb {
namespace {

using testing::FeatureWorld;

SystemOptions Options(const FeatureWorld& world, RunMode mode) {
  SystemOptions options;
  options.sensor = world.sensor();
  options.run_mode = mode;
  return options;
}

double TrajectoryRmse(const Trajectory& trajectory) {
  double sum_sq = 0.0;
  for (const StampedPose& p : trajectory) {
    const int k = static_cast<int>(std::lround(p.timestamp_s * 30.0));
    sum_sq += (p.world_from_cam.translation - testing::TruthInFirstCamera(k).Inverse().translation)
                  .squaredNorm();
  }
  return std::sqrt(sum_sq / trajectory.size());
}

Trajectory RunWorld(RunMode mode, int frames) {
  FeatureWorld world(21);
  System system(Options(world, mode));
  for (int k = 0; k < frames; ++k)
    system.ProcessFeatures(k / 30.0, world.Observe(FeatureWorld::WorldFromCam(k), 100 + k));
  system.Finish();
  return system.FrameTrajectory();
}

TEST(System, SequentialModeIsAccurateAndBitReproducible) {
  const Trajectory a = RunWorld(RunMode::kSequential, 120);
  const Trajectory b = RunWorld(RunMode::kSequential, 120);
  ASSERT_EQ(a.size(), 120u);
  ASSERT_EQ(b.size(), a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].world_from_cam.ToMatrix(), b[i].world_from_cam.ToMatrix()) << i;
  }
  EXPECT_LT(TrajectoryRmse(a), 0.012);
}

TEST(System, ParallelModeTracksEveryFrame) {
  const Trajectory t = RunWorld(RunMode::kParallel, 120);
  ASSERT_EQ(t.size(), 120u);
  EXPECT_LT(TrajectoryRmse(t), 0.015);
}

// Rejects every keypoint left of x = 256 and reports that strip as its dynamic mask.
class LeftStripFilter : public KeypointFilter {
 public:
  std::string name() const override { return "left-strip"; }
  bool MaskCoversDetections() const override { return true; }
  FilterOutput Filter(const FilterInput& input) override {
    FilterOutput out;
    for (const cv::KeyPoint& k : input.keypoints->keypoints) out.keep.push_back(k.pt.x >= 256.f);
    out.dynamic_mask = cv::Mat::zeros(input.gray->size(), CV_8U);
    out.dynamic_mask.colRange(0, 256).setTo(255);
    return out;
  }
};

TEST(System, RefillSpendsTheFeatureBudgetOutsideTheFilteredArea) {
  FeatureWorld world(1);
  cv::Mat gray = MakeSyntheticTexture(cv::Size(640, 480), 11), bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.f));
  for (const bool refill : {false, true}) {
    SystemOptions options = Options(world, RunMode::kSequential);
    options.refill_filtered = refill;
    System system(options, std::make_unique<LeftStripFilter>());
    const FrameRecord& r = system.ProcessFrame(0.0, bgr, depth);
    SCOPED_TRACE(refill);
    EXPECT_GT(r.num_filtered, 200);
    const int kept = r.num_keypoints - r.num_filtered;
    if (!refill) {
      EXPECT_EQ(r.num_refilled, 0);
      continue;
    }
    // The refill keeps about the full budget, all right of the strip (plus the disk margin).
    EXPECT_GT(r.num_refilled, kept + r.num_filtered / 2);
    EXPECT_GE(r.num_refilled, r.num_keypoints * 9 / 10);
    const Trajectory keyframes = system.KeyframeTrajectory();
    EXPECT_EQ(keyframes.size(), 1u);  // Initialised from the refilled features.
  }
}

// Keeps everything but says it could not judge its first frame (like the FAST cues).
class UnjudgedFirstFrameFilter : public KeypointFilter {
 public:
  std::string name() const override { return "unjudged-first"; }
  FilterOutput Filter(const FilterInput& input) override {
    FilterOutput out;
    out.keep.assign(input.keypoints->keypoints.size(), true);
    out.judged = calls_++ > 0;
    return out;
  }

 private:
  int calls_ = 0;
};

TEST(System, NeverInitializesFromAFrameTheFilterCouldNotJudge) {
  FeatureWorld world(1);
  cv::Mat gray = MakeSyntheticTexture(cv::Size(640, 480), 11), bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.f));
  System system(Options(world, RunMode::kSequential), std::make_unique<UnjudgedFirstFrameFilter>());
  const FrameRecord first = system.ProcessFrame(0.0, bgr, depth);
  EXPECT_EQ(first.state, TrackingState::kNotInitialized);
  EXPECT_EQ(first.num_filtered, first.num_keypoints);  // Withheld.
  const FrameRecord second = system.ProcessFrame(1.0 / 30.0, bgr, depth);
  EXPECT_EQ(second.state, TrackingState::kOk);
  EXPECT_TRUE(second.new_keyframe);
  EXPECT_EQ(second.num_filtered, 0);
  EXPECT_EQ(system.KeyframeTrajectory().size(), 1u);
}

TEST(System, RecordsTheKeypointsThePoseRestsOnAndTheNewLandmarks) {
  FeatureWorld world(1);
  cv::Mat gray = MakeSyntheticTexture(cv::Size(640, 480), 11), bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.f));
  System system(Options(world, RunMode::kSequential));
  system.set_record_keypoints(true);
  const FrameRecord first = system.ProcessFrame(0.0, bgr, depth);
  ASSERT_TRUE(first.new_keyframe);
  EXPECT_TRUE(first.inliers.empty());                      // The first keyframe is not tracked ...
  EXPECT_EQ(first.new_landmarks.size(), first.detected.size());  // ... every keypoint with depth seeds the map.
  const FrameRecord second = system.ProcessFrame(1.0 / 30.0, bgr, depth);
  ASSERT_TRUE(second.pose_valid);
  EXPECT_EQ(static_cast<int>(second.inliers.size()), second.num_inliers);
  EXPECT_GT(second.num_inliers, 500);
  for (const cv::KeyPoint& k : second.inliers) {  // Each is one of the frame's keypoints.
    EXPECT_TRUE(std::any_of(second.detected.begin(), second.detected.end(),
                            [&k](const cv::KeyPoint& d) { return d.pt == k.pt && d.octave == k.octave; }));
  }
  System quiet(Options(world, RunMode::kSequential));  // Not recorded unless asked.
  quiet.ProcessFrame(0.0, bgr, depth);
  EXPECT_TRUE(quiet.ProcessFrame(1.0 / 30.0, bgr, depth).inliers.empty());
}

TEST(System, RejectsBadImages) {
  FeatureWorld world(1);
  System system(Options(world, RunMode::kSequential));
  EXPECT_THROW(system.ProcessFrame(0.0, cv::Mat(480, 640, CV_8UC1), cv::Mat(480, 640, CV_32F)),
               InputError);
  EXPECT_THROW(system.ProcessFrame(0.0, cv::Mat(480, 640, CV_8UC3), cv::Mat(240, 320, CV_32F)),
               InputError);
}

}  // namespace
}  // namespace dynorb
