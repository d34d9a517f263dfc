// FAST dynamic mode: per-frame cost of FastFilter::Filter and its keypoint precision/recall on a
// short synthetic walking_xyz clip rendered in memory (frames 100-119, seed 7), for both
// correspondence methods (LK optical flow vs brute-force descriptor matching) and with single
// stages switched off. Counters: ms_per_frame (filter only), per-stage ms, precision, recall,
// process_cpu_ms_per_frame (all threads); *_1thread: OpenCV on one thread.
//   build/<dir>/bench/dynorb_microbench --benchmark_filter=FastFilter
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "bench_util.h"
#include "dynorb/dynamic/fast_correspondence.h"
#include "dynorb/dynamic/fast_filter.h"
#include "dynorb/synth/synthesizer.h"

namespace dynorb {
namespace {

struct Clip {
  PinholeCamera camera;
  std::vector<cv::Mat> bgr, gray, depth, mask;
  std::vector<Rigid3d> world_from_cam;
  std::vector<KeypointSet> keypoints;
};

const Clip& GetClip() {
  static const Clip clip = [] {
    synth::SynthOptions o;
    o.preset = "walking_xyz";
    o.seed = 7;
    o.frames = 150;
    synth::SequenceSynth synth(o);
    auto renderer = synth.MakeRenderer();
    Clip c;
    c.camera = synth.camera();
    const OrbExtractor extractor;
    for (int i = 100; i < 120; ++i) {
      const synth::SynthFrame f = synth.RenderFrame(i, renderer.get());
      cv::Mat gray, depth;
      cv::cvtColor(f.rgb, gray, cv::COLOR_BGR2GRAY);
      f.depth_u16.convertTo(depth, CV_32F, 1.0 / 5000.0);
      c.bgr.push_back(f.rgb);
      c.gray.push_back(gray);
      c.depth.push_back(depth);
      c.mask.push_back(f.mask);
      c.world_from_cam.push_back(f.world_from_cam);
      c.keypoints.push_back(extractor.Detect(gray));
    }
    return c;
  }();
  return clip;
}

// `one_thread`: OpenCV limited to one thread. `process_cpu_ms_per_frame`: the whole process's CPU
// (ProcessCpuTimer).
void RunFast(benchmark::State& state, FastOptions options, bool one_thread = false) {
  const Clip& clip = GetClip();
  long long tp = 0, fp = 0, fn = 0;
  FastTiming stages;
  int frames = 0;
  const CvThreads threads(one_thread ? 1 : 0);
  const ProcessCpuTimer cpu;
  for (auto _ : state) {
    FastFilter filter(options, clip.camera);
    for (size_t i = 0; i < clip.gray.size(); ++i) {
      FilterInput input;
      input.bgr = &clip.bgr[i];
      input.gray = &clip.gray[i];
      input.depth_m = &clip.depth[i];
      input.keypoints = &clip.keypoints[i];
      if (i >= 2) input.predicted_cam_from_previous_cam = clip.world_from_cam[i - 1].Inverse() * clip.world_from_cam[i - 2];
      const FilterOutput out = filter.Filter(input);
      benchmark::DoNotOptimize(out.keep);
      if (i == 0) continue;
      const auto& kps = clip.keypoints[i].keypoints;
      for (size_t k = 0; k < kps.size(); ++k) {
        const cv::Point p(std::clamp(static_cast<int>(std::lround(kps[k].pt.x)), 0, clip.mask[i].cols - 1),
                          std::clamp(static_cast<int>(std::lround(kps[k].pt.y)), 0, clip.mask[i].rows - 1));
        const bool truth = clip.mask[i].at<uint8_t>(p) != 0, removed = !out.keep[k];
        tp += truth && removed;
        fp += !truth && removed;
        fn += truth && !removed;
      }
    }
    stages += filter.total_timing();
    frames += filter.frames();
  }
  const double cpu_ms = cpu.ElapsedMs();
  const double f = std::max(1, frames);
  state.counters["ms_per_frame"] = stages.total_ms / f;
  state.counters["process_cpu_ms_per_frame"] = cpu_ms / f;
  state.counters["flow_ms"] = stages.flow_ms / f;
  state.counters["ego_ms"] = stages.ego_ms / f;
  state.counters["F_ms"] = stages.fundamental_ms / f;
  state.counters["cues_ms"] = stages.cues_ms / f;
  state.counters["region_ms"] = stages.region_ms / f;
  state.counters["precision"] = tp + fp > 0 ? static_cast<double>(tp) / (tp + fp) : 0.0;
  state.counters["recall"] = tp + fn > 0 ? static_cast<double>(tp) / (tp + fn) : 0.0;
}

void BM_FastFilter_Flow(benchmark::State& state) { RunFast(state, FastOptions()); }
void BM_FastFilter_Flow_1thread(benchmark::State& state) { RunFast(state, FastOptions(), true); }
void BM_FastFilter_Descriptors(benchmark::State& state) {
  FastOptions o;
  o.correspondences = "descriptors";
  RunFast(state, o);
}
// The seed report's cues only (F-RANSAC epipolar, direction, magnitude; no depth, no regions).
void BM_FastFilter_ReportCuesOnly_Flow(benchmark::State& state) {
  FastOptions o;
  o.use_residual = o.use_depth = o.use_region = false;
  o.suspect_frames = 0;
  o.track_min_moving = 99;
  RunFast(state, o);
}
void BM_FastFilter_ReportCuesOnly_Descriptors(benchmark::State& state) {
  FastOptions o;
  o.correspondences = "descriptors";
  o.use_residual = o.use_depth = o.use_region = false;
  o.suspect_frames = 0;
  o.track_min_moving = 99;
  RunFast(state, o);
}
void BM_FastFilter_NoRegion(benchmark::State& state) {
  FastOptions o;
  o.use_region = false;
  RunFast(state, o);
}

// The flow stage's two parts on the same clip: the LK pyramid (with derivatives) of one frame,
// and tracking the filter's 400-point subset from one frame to the previous one.
void BM_FastFlow_Pyramid(benchmark::State& state) {
  const Clip& clip = GetClip();
  const LkOptions lk;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(BuildLkPyramid(clip.gray[i], lk));
    i = (i + 1) % clip.gray.size();
  }
}
void BM_FastFlow_Track(benchmark::State& state) {
  const Clip& clip = GetClip();
  LkOptions lk;
  lk.backward_check = false;
  std::vector<std::vector<cv::Mat>> pyramids;
  for (const cv::Mat& g : clip.gray) pyramids.push_back(BuildLkPyramid(g, lk));
  size_t i = 1;
  for (auto _ : state) {
    const auto& kps = clip.keypoints[i].keypoints;
    std::vector<cv::Point2f> points;
    for (const auto& kp : kps) points.push_back(kp.pt);
    const std::vector<int> subset = SpreadSubset(kps, clip.gray[i].size(), static_cast<int>(state.range(0)));
    benchmark::DoNotOptimize(TrackSubsetWithFlow(pyramids[i - 1], pyramids[i], points, subset, {}, lk));
    i = i + 1 < clip.gray.size() ? i + 1 : 1;
  }
}
// LK on the base image first (lk_base_first_px) with a window of state.range(0) px (0: the
// 21 px default), from guesses 0.5 px off the full pyramid's answer (what a one-frame-old
// ego-motion gives); the points that end > 1 px off are tracked again through the pyramid.
void BM_FastFlow_BaseFirst(benchmark::State& state) {
  const Clip& clip = GetClip();
  LkOptions lk;
  lk.backward_check = false;
  std::vector<std::vector<cv::Mat>> pyramids;
  for (const cv::Mat& g : clip.gray) pyramids.push_back(BuildLkPyramid(g, lk));
  struct Pair {
    std::vector<cv::Point2f> points, guesses;
    std::vector<int> subset;
  };
  std::vector<Pair> pairs(clip.gray.size());
  for (size_t i = 1; i < clip.gray.size(); ++i) {
    for (const auto& kp : clip.keypoints[i].keypoints) pairs[i].points.push_back(kp.pt);
    pairs[i].subset = SpreadSubset(clip.keypoints[i].keypoints, clip.gray[i].size(), 400);
    const Correspondences full =
        TrackSubsetWithFlow(pyramids[i - 1], pyramids[i], pairs[i].points, pairs[i].subset, {}, lk);
    for (int k : pairs[i].subset)
      pairs[i].guesses.push_back(full.previous[k] + cv::Point2f(0.5f, -0.5f));
  }
  lk.base_first_px = 1.0;
  lk.base_window_px = static_cast<int>(state.range(0));
  lk.epsilon_px = state.range(1) / 100.0;
  size_t i = 1;
  for (auto _ : state) {
    const Pair& p = pairs[i];
    benchmark::DoNotOptimize(
        TrackSubsetWithFlow(pyramids[i - 1], pyramids[i], p.points, p.subset, p.guesses, lk));
    i = i + 1 < clip.gray.size() ? i + 1 : 1;
  }
}

BENCHMARK(BM_FastFlow_Pyramid)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FastFlow_Track)->Arg(400)->Arg(200)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FastFlow_BaseFirst)
    ->Args({0, 1})
    ->Args({15, 1})
    ->Args({11, 1})
    ->Args({9, 1})
    ->Args({7, 1})
    ->Args({11, 3})
    ->Args({11, 5})
    ->Args({11, 10})
    ->ArgNames({"base_window_px", "epsilon_centipx"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FastFilter_Flow)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_FastFilter_Flow_1thread)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_FastFilter_Descriptors)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_FastFilter_ReportCuesOnly_Flow)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_FastFilter_ReportCuesOnly_Descriptors)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_FastFilter_NoRegion)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace
}  // namespace dynorb
