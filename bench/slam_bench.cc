// The SLAM loop on a rendered office sequence held in memory (no PNG decoding), so the numbers are
// the system's own cost: ORB extraction, tracking, local mapping with BA.
//   build/<dir>/bench/dynorb_microbench --benchmark_filter=Slam
// Counters: frames_per_s (wall, the issue's >= 30 Hz target for sequential mode), ms_per_frame,
// keyframes and ate_mm (accuracy of the same run against the exact ground truth).
// Inputs: the static twin of walking_xyz / walking_rpy, 150 frames, fr3 intrinsics, 1000 ORB
// features (the defaults of `dynorb run` on `dynorb synth` output).
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "dynorb/core/timer.h"
#include "dynorb/eval/evaluate.h"
#include "dynorb/synth/synthesizer.h"
#include "dynorb/system/system.h"

namespace {

struct MemoryFrame {
  double timestamp_s = 0.0;
  cv::Mat rgb, depth_m;
  dynorb::Rigid3d world_from_cam;
};

const std::vector<MemoryFrame>& Frames(const std::string& preset) {
  static std::map<std::string, std::vector<MemoryFrame>> cache;
  auto it = cache.find(preset);
  if (it != cache.end()) return it->second;
  dynorb::synth::SynthOptions options;
  options.preset = preset;
  options.seed = 7;
  options.frames = 150;
  options.static_twin = true;
  const dynorb::synth::SequenceSynth sequence(options);
  auto renderer = sequence.MakeRenderer();
  std::vector<MemoryFrame> frames;
  for (int i = 0; i < sequence.num_frames(); ++i) {
    const dynorb::synth::SynthFrame f = sequence.RenderFrame(i, renderer.get());
    MemoryFrame m;
    m.timestamp_s = f.time.rgb_ts;
    m.rgb = f.rgb;
    f.depth_u16.convertTo(m.depth_m, CV_32F,
                          1.0 / 5000.0);  // The sensor's depth, as dynorb run reads it.
    m.world_from_cam = f.world_from_cam;
    frames.push_back(std::move(m));
  }
  return cache.emplace(preset, std::move(frames)).first->second;
}

void BM_SlamLoop(benchmark::State& state, const std::string& preset, dynorb::RunMode mode) {
  const std::vector<MemoryFrame>& frames = Frames(preset);
  dynorb::SystemOptions options;
  options.sensor.camera.fx = 535.4;
  options.sensor.camera.fy = 539.2;
  options.sensor.camera.cx = 320.1;
  options.sensor.camera.cy = 247.6;
  options.sensor.camera.width = 640;
  options.sensor.camera.height = 480;
  options.sensor.bf = 40.0;
  options.sensor.th_depth_m = 40.0 * 40.0 / options.sensor.camera.fx;
  options.run_mode = mode;
  int processed = 0, keyframes = 0;
  double ate_m = 0.0;
  double processing_ms = 0.0;
  for (auto _ : state) {
    const dynorb::Stopwatch watch;
    dynorb::System system(options);
    for (const MemoryFrame& f : frames) system.ProcessFrame(f.timestamp_s, f.rgb, f.depth_m);
    system.Finish();
    processing_ms += watch.ElapsedMs();
    processed += static_cast<int>(frames.size());
    state.PauseTiming();
    dynorb::Trajectory truth;
    for (const MemoryFrame& f : frames) truth.push_back({f.timestamp_s, f.world_from_cam});
    ate_m = dynorb::EvaluateTrajectories(truth, system.FrameTrajectory(), dynorb::EvalOptions())
                .ate.stats.rmse;
    keyframes = static_cast<int>(system.KeyframeTrajectory().size());
    state.ResumeTiming();
  }
  state.counters["frames_per_s"] = benchmark::Counter(processed, benchmark::Counter::kIsRate);
  state.counters["ms_per_frame"] = processed == 0 ? 0.0 : processing_ms / processed;
  state.counters["keyframes"] = keyframes;
  state.counters["ate_mm"] = ate_m * 1000.0;
}

BENCHMARK_CAPTURE(BM_SlamLoop, walking_xyz_twin_sequential, std::string("walking_xyz"),
                  dynorb::RunMode::kSequential)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);
BENCHMARK_CAPTURE(BM_SlamLoop, walking_rpy_twin_sequential, std::string("walking_rpy"),
                  dynorb::RunMode::kSequential)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);
BENCHMARK_CAPTURE(BM_SlamLoop, walking_xyz_twin_parallel, std::string("walking_xyz"),
                  dynorb::RunMode::kParallel)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

}  // namespace
