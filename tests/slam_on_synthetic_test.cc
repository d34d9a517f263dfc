// System test: the full SLAM pipeline (ORB extraction, tracking, local mapping, BA) in
// sequential mode on a short rendered office sequence (the static twin of walking_xyz), scored
// with the TUM ATE definition against the exact ground truth.
#include <gtest/gtest.h>

#include "dynorb/eval/evaluate.h"
#include "dynorb/synth/synthesizer.h"
#include "dynorb/system/system.h"

namespace dynorb {
namespace {

struct RunResult {
  Trajectory estimate;
  Trajectory truth;
  int tracked = 0;
};

RunResult RenderAndTrack(int frames) {
  synth::SynthOptions options;
  options.preset = "walking_xyz";
  options.seed = 3;
  options.frames = frames;
  options.static_twin = true;
  options.threads = 1;
  const synth::SequenceSynth sequence(options);
  std::unique_ptr<synth::Renderer> renderer = sequence.MakeRenderer();

  SystemOptions system_options;
  system_options.sensor.camera = sequence.camera();
  system_options.sensor.bf = 40.0;
  system_options.sensor.th_depth_m = 40.0 * 40.0 / sequence.camera().fx;
  System system(system_options);
  RunResult result;
  for (int i = 0; i < sequence.num_frames(); ++i) {
    const synth::SynthFrame frame = sequence.RenderFrame(i, renderer.get());
    cv::Mat depth_m;
    frame.depth_u16.convertTo(depth_m, CV_32F, 1.0 / 5000.0);
    const FrameRecord& record = system.ProcessFrame(frame.time.rgb_ts, frame.rgb, depth_m);
    result.tracked += record.pose_valid ? 1 : 0;
    result.truth.push_back({frame.time.rgb_ts, frame.world_from_cam});
  }
  system.Finish();
  result.estimate = system.FrameTrajectory();
  return result;
}

TEST(SlamOnSyntheticOffice, StaticSequenceIsTrackedAccurately) {
  const RunResult r = RenderAndTrack(90);
  EXPECT_EQ(r.tracked, 90);
  const EvalResult eval = EvaluateTrajectories(r.truth, r.estimate, EvalOptions());
  EXPECT_EQ(eval.ate.stats.count, 90);
  EXPECT_LT(eval.ate.stats.rmse, 0.015) << "ATE RMSE " << eval.ate.stats.rmse << " m";
}

}  // namespace
}  // namespace dynorb
