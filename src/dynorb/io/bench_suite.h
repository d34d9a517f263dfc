// BenchSuite: the YAML description of a `dynorb bench` run (docs/benchmark.md): which sequences
// (TUM-format folders or synthetic presets) are run with which modes, how often, with which seeds.
//
//   name: quick
//   repeats: 2                  # runs per (sequence, mode); seeds 1..repeats unless `seeds:`
//   sequences:
//     - name: syn_walking_xyz
//       synthetic: {preset: walking_xyz, seed: 1, frames: 60, static_twin: true, view_loss: true}
//     - name: fr3_walking_xyz
//       path: rgbd_dataset_freiburg3_walking_xyz   # relative to --dataset-root (or the suite)
//       config: ../../config/tum_fr3.yaml          # relative to the suite file
//       tum_name: fr3/walking_xyz                  # key of bench/published_results.json
//   modes:
//     - plain
//     - {name: fast, config: fast_strict.yaml}     # replaces the sequence's config for this mode
//     - {name: fast, overlay: fast_bf.yaml}        # applied over the sequence's config
//     - {name: semantic, optional: true}           # skipped (warning) if this build lacks it
//
// Parsing only checks the file itself (types, unknown keys, duplicates, file:line in every
// error); whether modes are registered and folders exist is checked by the caller, which gets
// the line of every entry for its messages. Pure data, no I/O besides reading the file.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace dynorb {

struct BenchSyntheticSpec {
  std::string preset;       // synth preset name (validated by the generator)
  uint64_t seed = 1;        // generator seed (the SLAM seeds vary per repeat)
  int frames = 0;           // 0: the preset's full length
  bool static_twin = true;  // also generate and run the static twin
  // Also run the view-loss reference: the twin's images with this sequence's ground-truth masks
  // (docs/benchmark.md), as sequence "<name>_viewloss". Needs static_twin.
  bool view_loss = false;
};

// Name suffix of a sequence's view-loss reference run (reserved like "_twin").
inline constexpr const char* kViewLossSuffix = "_viewloss";

struct BenchSequence {
  std::string name;  // unique, [A-Za-z0-9_.-]+; used in output paths
  std::string path;  // TUM-format folder (as written); empty for synthetic
  bool synthetic = false;
  BenchSyntheticSpec synth;  // when synthetic
  std::string config;        // YAML resolved against the suite's folder; empty: camera.yaml
  std::string frames;        // "A:B" or empty
  std::string tum_name;      // e.g. "fr3/walking_xyz": published numbers to show
  int line = 0;              // line in the suite file
};

struct BenchMode {
  std::string name;    // a registered run mode (checked by the caller)
  std::string config;  // optional: config replacing the sequence's one, resolved against the suite
  std::string overlay;  // optional: YAML applied over the (sequence's or mode's) config, e.g. a
                        // mode section; resolved against the suite (`dynorb run --config-overlay`)
  std::string label;    // column label; default: name (+ config and overlay file stems)
  bool optional = false;  // skipped with a warning when the mode is not registered in this build
  int line = 0;
};

// Deepest pipeline of `dynorb run --pipeline-depth` and of a suite's `pipeline_depth` (the run
// keeps depth + 1 decoded frames in hand).
inline constexpr int kMaxPipelineDepth = 16;

struct BenchSuite {
  std::string file;  // path as given
  std::string name;
  std::string description;
  int repeats = 1;
  std::vector<uint64_t> seeds;  // explicit SLAM seeds; empty: 1..repeats
  std::string run_mode = "sequential";
  bool pipeline = true;  // `dynorb run --pipeline` (the default) or --no-pipeline.
  int pipeline_depth = 4;  // `dynorb run --pipeline-depth` (same default), 1..kMaxPipelineDepth.
  int front_end_threads = 0;  // `dynorb run --front-end-threads` (same default): 0 (auto), 1 or 2.
  bool preload = false;  // `dynorb run --preload`: frames decoded before each run (live-camera timing).
  bool save_map = false;  // `dynorb run --save-map`: each run's final map as map.ply.
  std::vector<BenchSequence> sequences;
  std::vector<BenchMode> modes;

  // The SLAM seeds of the runs: 1..repeats_override if > 0, else `seeds` if given, else 1..repeats.
  std::vector<uint64_t> RunSeeds(int repeats_override) const;
};

// Throws InputError ("file:line: ...") for unreadable files, bad YAML, unknown or duplicate keys,
// wrong types, no sequences/modes, duplicate names, a sequence with both/neither path and
// synthetic.
BenchSuite LoadBenchSuite(const std::string& path);
BenchSuite ParseBenchSuite(const std::string& yaml_text, const std::string& source_name,
                           const std::string& base_dir);

}  // namespace dynorb
