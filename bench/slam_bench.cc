// The SLAM loop on a rendered office sequence held in memory (no PNG decoding), so the numbers are
// the system's own cost: ORB extraction, tracking, local mapping with BA.
//   build/<dir>/bench/dynorb_microbench --benchmark_filter=Slam
// Counters: frames_per_s (wall, the issue's >= 30 Hz target for sequential mode), ms_per_frame,
// keyframes and ate_mm (accuracy of the same run against the exact ground truth).
// Inputs: the static twin of walking_xyz / walking_rpy, 150 frames, fr3 intrinsics, 1000 ORB
// features (the defaults of `dynorb run` on `dynorb synth` output). The `dynamic_*` cases run the
// walking_xyz sequence with its (procedural) people, plain or with the FAST filter, without and
// with pipelining (System::ProcessFrame's `next`): fast/plain of the same case pair is the
// filter's cost with no PNG decoding competing for the two cores.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "dynorb/core/timer.h"
#include "dynorb/dynamic/fast_filter.h"
#include "dynorb/eval/evaluate.h"
#include "dynorb/synth/synthesizer.h"
#include "dynorb/system/system.h"

namespace {

struct MemoryFrame {
  double timestamp_s = 0.0;
  cv::Mat rgb, depth_m;
  dynorb::Rigid3d world_from_cam;
};

const std::vector<MemoryFrame>& Frames(const std::string& preset, bool twin = true) {
  static std::map<std::string, std::vector<MemoryFrame>> cache;
  const std::string key = preset + (twin ? "/twin" : "/dynamic");
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  dynorb::synth::SynthOptions options;
  options.preset = preset;
  options.seed = 7;
  options.frames = 150;
  options.static_twin = twin;
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
  return cache.emplace(key, std::move(frames)).first->second;
}

struct LoopCase {
  dynorb::RunMode mode = dynorb::RunMode::kSequential;
  bool twin = true;
  bool fast_filter = false;
  bool pipelined = false;
};

void BM_SlamLoop(benchmark::State& state, const std::string& preset, LoopCase loop) {
  const std::vector<MemoryFrame>& frames = Frames(preset, loop.twin);
  dynorb::SystemOptions options;
  options.sensor.camera.fx = 535.4;
  options.sensor.camera.fy = 539.2;
  options.sensor.camera.cx = 320.1;
  options.sensor.camera.cy = 247.6;
  options.sensor.camera.width = 640;
  options.sensor.camera.height = 480;
  options.sensor.bf = 40.0;
  options.sensor.th_depth_m = 40.0 * 40.0 / options.sensor.camera.fx;
  options.run_mode = loop.mode;
  int processed = 0, keyframes = 0;
  double ate_m = 0.0;
  double processing_ms = 0.0;
  for (auto _ : state) {
    const dynorb::Stopwatch watch;
    std::unique_ptr<dynorb::KeypointFilter> filter;
    if (loop.fast_filter) filter = std::make_unique<dynorb::FastFilter>(dynorb::FastOptions(), options.sensor.camera);
    dynorb::System system(options, std::move(filter));
    for (size_t i = 0; i < frames.size(); ++i) {
      dynorb::System::NextFrame next;
      const bool has_next = loop.pipelined && i + 1 < frames.size();
      if (has_next) next = {frames[i + 1].timestamp_s, frames[i + 1].rgb, frames[i + 1].depth_m, false};
      system.ProcessFrame(frames[i].timestamp_s, frames[i].rgb, frames[i].depth_m, has_next ? &next : nullptr);
    }
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

#define DYNORB_SLAM_LOOP(name, preset, ...)                                   \
  BENCHMARK_CAPTURE(BM_SlamLoop, name, std::string(preset), LoopCase{__VA_ARGS__}) \
      ->Unit(benchmark::kMillisecond)                                       \
      ->UseRealTime()                                                       \
      ->Iterations(2)

constexpr dynorb::RunMode kSeq = dynorb::RunMode::kSequential;
DYNORB_SLAM_LOOP(walking_xyz_twin_sequential, "walking_xyz", kSeq, true, false, false);
DYNORB_SLAM_LOOP(walking_rpy_twin_sequential, "walking_rpy", kSeq, true, false, false);
DYNORB_SLAM_LOOP(walking_xyz_twin_parallel, "walking_xyz", dynorb::RunMode::kParallel, true, false, false);
DYNORB_SLAM_LOOP(dynamic_xyz_plain, "walking_xyz", kSeq, false, false, false);
DYNORB_SLAM_LOOP(dynamic_xyz_plain_pipelined, "walking_xyz", kSeq, false, false, true);
DYNORB_SLAM_LOOP(dynamic_xyz_fast, "walking_xyz", kSeq, false, true, false);
DYNORB_SLAM_LOOP(dynamic_xyz_fast_pipelined, "walking_xyz", kSeq, false, true, true);

}  // namespace
