// `dynorb bench` execution: expands a BenchSuite into runs (sequence x mode x seed), checks
// everything a run needs before the first one starts (registered modes, dataset folders, config
// files, synth presets), generates synthetic sequences (and their static twins) into a cache,
// runs RunPipeline() for every run not done yet (resume: a run is done when its stats.json
// exists; RunPipeline writes it atomically, last), draws plots and writes results.json.
//
// Output layout (docs/benchmark.md):
//   OUT/cache/<preset>_s<seed>_f<frames>[_twin]/    synthetic sequences (reused)
//   OUT/cache/<preset>_s<seed>_f<frames>_viewloss.yaml
//                                                   config of a view-loss reference run
//   OUT/runs/<sequence>/<mode>/seed<k>/             RunPipeline outputs (stats.json, ...)
//   OUT/plots/<sequence>__<mode>.{png,svg}          trajectory vs ground truth, error over time
//   OUT/plots/<sequence>__<mode>_keypoints.png      kept (green) / removed (red) keypoints
//   OUT/results.json                                every run (see BuildResultsJson)
// Single-threaded driver (each run may use the parallel run mode).
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "dynorb/io/bench_suite.h"

namespace dynorb {

struct BenchOptions {
  std::string suite;         // suite YAML
  std::string out;           // output folder
  int repeats = 0;           // > 0 overrides the suite's repeats/seeds (seeds 1..N)
  std::string dataset_root;  // folder the suite's relative `path:` entries are resolved against
  bool skip_missing =
      false;           // skip real sequences whose folder is missing (warning) instead of failing
  bool plots = true;   // trajectory plots and keypoint strips
  bool quiet = false;  // no progress bar
  std::string people_dir =
      "auto";          // synthetic people cut-outs ("auto": ../shared/data/people if present)
  std::string models;  // detector models (semantic modes)
};

// Label (mode column) of the view-loss reference runs: mode "semantic" with the dynamic
// sequence's ground-truth masks on the static twin's images (docs/benchmark.md).
inline constexpr const char* kViewLossLabel = "view_loss";

// One sequence as run: a suite entry, the static twin of a synthetic one, or its view-loss
// reference.
struct BenchSequenceRun {
  std::string name;     // e.g. syn_walking_xyz or syn_walking_xyz_twin
  std::string dataset;  // folder (for synthetic: the cache folder, maybe not generated yet)
  std::string config;   // empty: dataset/camera.yaml
  std::string frames;
  std::string tum_name;
  std::string twin_of;  // for a twin: the dynamic sequence's name
  bool synthetic = false;
  BenchSyntheticSpec synth;
  bool twin = false;
  // For a view-loss reference: the dynamic sequence's name and folder (whose masks.txt is used);
  // `dataset` is the twin's folder, `config` the file RunBench writes before the runs.
  std::string view_loss_of;
  std::string masks_dataset;
  std::string view_loss_base_config;  // the twin's config the reference's config starts from
};

struct BenchRun {
  const BenchSequenceRun* sequence = nullptr;
  const BenchMode* mode = nullptr;
  uint64_t seed = 0;
  int repeat = 0;       // 0-based index of the seed
  std::string out_dir;  // OUT/runs/<sequence>/<mode>/seed<k>
};

struct BenchPlan {
  BenchPlan() = default;
  // `runs` point into `sequences` and `suite.modes`: a move keeps them valid, a copy would not.
  BenchPlan(BenchPlan&&) = default;
  BenchPlan(const BenchPlan&) = delete;
  BenchPlan& operator=(const BenchPlan&) = delete;

  BenchSuite suite;
  std::vector<BenchSequenceRun> sequences;
  // The view-loss reference's mode (kViewLossLabel), the only one its sequences run; none
  // without such sequences. Held by pointer so that `runs` stay valid when the plan moves.
  std::unique_ptr<BenchMode> view_loss_mode;
  std::vector<BenchRun> runs;  // sequence-major, then mode, then seed
  std::vector<std::string> warnings;
};

// Loads the suite and checks it against the registered modes and the file system (a view-loss
// reference needs the modes "semantic", registered, and "plain", in the suite). Throws
// InputError (suite file:line for entries) before anything is written.
BenchPlan PlanBench(const BenchOptions& options);

// Runs the plan (generating synthetic sequences first), writes OUT/results.json and the plots;
// returns results.json's content. Runs whose stats.json exists are not run again.
nlohmann::json RunBench(const BenchOptions& options, const BenchPlan& plan);

}  // namespace dynorb
