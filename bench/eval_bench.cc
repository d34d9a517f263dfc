// Benchmarks of the trajectory evaluator (dynorb/eval): association, and the full ATE + RPE +
// coverage evaluation of `dynorb eval` on long trajectories (target: 100 000 poses well under 1 s).
#include <benchmark/benchmark.h>

#include <map>

#include "dynorb/eval/evaluate.h"
#include "dynorb/eval/trajectory_generator.h"

namespace dynorb {
namespace {

// Ground truth and estimate with `poses` poses each at 30 Hz (a ~55 min sequence for 100 000).
const TrajectoryPair& Pair(int poses) {
  static std::map<int, TrajectoryPair> cache;
  auto it = cache.find(poses);
  if (it == cache.end()) {
    TrajectoryPairOptions o;
    o.seed = 3;
    o.rate_hz = 30.0;
    o.duration_s = (poses - 1) / o.rate_hz;
    o.drop_fraction = 0.0;
    it = cache.emplace(poses, GenerateTrajectoryPair(o)).first;
  }
  return it->second;
}

void BM_EvaluateAteRpe(benchmark::State& state) {
  const TrajectoryPair& pair = Pair(static_cast<int>(state.range(0)));
  EvalOptions options;
  for (auto _ : state) {
    const EvalResult r = EvaluateTrajectories(pair.groundtruth, pair.estimate, options);
    benchmark::DoNotOptimize(r.ate.stats.rmse);
    benchmark::DoNotOptimize(r.rpe.trans_m.rmse);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_EvaluateAteRpe)->Arg(1000)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_Associate(benchmark::State& state) {
  const TrajectoryPair& pair = Pair(static_cast<int>(state.range(0)));
  const std::vector<double> gt = Stamps(pair.groundtruth), est = Stamps(pair.estimate);
  StampAssociationOptions options;
  for (auto _ : state) benchmark::DoNotOptimize(AssociateStamps(gt, est, options).size());
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Associate)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace dynorb
