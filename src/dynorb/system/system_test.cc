#include "dynorb/system/system.h"

#include <gtest/gtest.h>

#include "dynorb/core/error.h"

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
    sum_sq += (p.world_from_cam.translation - testing::TruthInFirstCamera(k).Inverse().translation).squaredNorm();
  }
  return std::sqrt(sum_sq / trajectory.size());
}

Trajectory RunWorld(RunMode mode, int frames) {
  FeatureWorld world(21);
  System system(Options(world, mode));
  for (int k = 0; k < frames; ++k) system.ProcessFeatures(k / 30.0, world.Observe(FeatureWorld::WorldFromCam(k), 100 + k));
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

TEST(System, RejectsBadImages) {
  FeatureWorld world(1);
  System system(Options(world, RunMode::kSequential));
  EXPECT_THROW(system.ProcessFrame(0.0, cv::Mat(480, 640, CV_8UC1), cv::Mat(480, 640, CV_32F)), InputError);
  EXPECT_THROW(system.ProcessFrame(0.0, cv::Mat(480, 640, CV_8UC3), cv::Mat(240, 320, CV_32F)), InputError);
}

}  // namespace
}  // namespace dynorb
