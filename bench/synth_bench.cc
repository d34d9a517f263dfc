// Throughput of `dynorb synth`: one frame (render + sensor effects) on one thread, and the whole
// pipeline (render, noise, PNG writing) on all cores. Target: >= 20 frames/s on 2 cores.
//   build/<dir>/bench/dynorb_microbench --benchmark_filter=Synth
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <memory>

#include "bench_util.h"
#include "dynorb/synth/synthesizer.h"

namespace {

dynorb::synth::SynthOptions BenchOptions() {
  dynorb::synth::SynthOptions o;
  o.preset = "walking_xyz";
  o.seed = 7;
  o.frames = 60;
  if (std::filesystem::is_directory(DYNORB_SOURCE_DIR "/../shared/data/people"))
    o.people_dir = DYNORB_SOURCE_DIR "/../shared/data/people";
  return o;
}

void BM_SynthRenderFrame(benchmark::State& state) {
  static const auto synth = std::make_unique<dynorb::synth::SequenceSynth>(BenchOptions());
  auto renderer = synth->MakeRenderer();
  int k = 0;
  for (auto _ : state) {
    auto frame = synth->RenderFrame(k, renderer.get());
    benchmark::DoNotOptimize(frame.rgb.data);
    k = (k + 1) % synth->num_frames();
  }
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SynthRenderFrame)->Unit(benchmark::kMillisecond);

// End to end, as `dynorb synth --frames 60` (includes building the scene, ~1 s).
void BM_SynthSequence(benchmark::State& state) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("dynorb_synth_bench_" + std::to_string(::getpid()));
  int frames = 0;
  const dynorb::ProcessCpuTimer cpu;
  for (auto _ : state) {
    std::filesystem::remove_all(dir);
    auto o = BenchOptions();
    o.frames = static_cast<int>(state.range(0));
    o.out_dir = dir.string();
    frames += dynorb::synth::Synthesize(o).frames;
  }
  const double cpu_s = cpu.ElapsedMs() / 1000.0;
  std::filesystem::remove_all(dir);
  state.counters["frames_per_s"] = benchmark::Counter(frames, benchmark::Counter::kIsRate);
  // Frames per CPU second of the whole process (all threads): the rate one idle core sustains.
  state.counters["frames_per_cpu_s"] = frames / std::max(1e-9, cpu_s);
}
BENCHMARK(BM_SynthSequence)->Arg(150)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace
