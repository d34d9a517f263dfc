#include "bench_runner.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "bench_plots.h"
#include "build_id.h"
#include "builtin_config.h"
#include "dynorb/core/error.h"
#include "dynorb/io/atomic_file.h"
#include "dynorb/synth/camera_motion.h"
#include "dynorb/synth/synthesizer.h"
#include "progress_bar.h"
#include "run_modes.h"
#include "run_pipeline.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;

constexpr const char* kDefaultPeopleDir = "../shared/data/people";
// The keypoint strip of the report shows 4 frames: overlays of every 10th frame are plenty.
constexpr int kStripOverlayEvery = 10;

std::string CacheName(const BenchSyntheticSpec& s, bool twin) {
  return s.preset + "_s" + std::to_string(s.seed) + "_f" + std::to_string(s.frames) +
         (twin ? "_twin" : "");
}

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return text;
}

// A path as one spelling ("out", "./out/", an absolute path, a link: the same folder).
std::string SamePath(const std::string& path) {
  if (path.empty()) return path;
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(fs::absolute(path, ec), ec);
  return ec ? fs::path(path).lexically_normal().string() : canonical.string();
}

// The people cut-outs of generated sequences ("" = procedural figures).
std::string SynthPeopleDir(const BenchOptions& options) {
  if (options.people_dir == "auto")
    return fs::is_directory(kDefaultPeopleDir) ? kDefaultPeopleDir : "";
  return options.people_dir == "procedural" ? "" : options.people_dir;
}

// A cached sequence is reused only when its scene.yaml says it was made by this generator version
// (synth::kSynthVersion) with these people; others are generated again.
bool CachedSequenceIsCurrent(const std::string& dataset, const std::string& people_dir) {
  if (!fs::exists(fs::path(dataset) / "rgb.txt")) return false;
  std::ifstream scene(fs::path(dataset) / "scene.yaml");
  std::string line;
  bool version = false, people = false;
  while (std::getline(scene, line)) {
    if (line.rfind("synth_version:", 0) == 0)
      version = line == std::string("synth_version: ") + synth::kSynthVersion;
    if (line.rfind("people_dir:", 0) == 0 && line.size() >= 14 && line.back() == '\'') {
      people = SamePath(line.substr(13, line.size() - 14)) == SamePath(people_dir);
    }
  }
  return version && people;
}

// Generates one synthetic sequence into its cache folder unless a current one is there. The
// generator writes into a temporary sibling that is renamed when complete, so an interrupted
// generation is redone, never reused half-written.
void EnsureSynthetic(const BenchSequenceRun& seq, const BenchOptions& options) {
  const std::string people_dir = SynthPeopleDir(options);
  if (CachedSequenceIsCurrent(seq.dataset, people_dir)) return;
  const std::string temp = seq.dataset + ".partial";
  std::error_code ec;
  fs::remove_all(seq.dataset, ec);
  fs::remove_all(temp, ec);
  fs::create_directories(fs::path(seq.dataset).parent_path(), ec);
  synth::SynthOptions o;
  o.preset = seq.synth.preset;
  o.seed = seq.synth.seed;
  o.frames = seq.synth.frames;
  o.static_twin = seq.twin;
  o.out_dir = temp;
  o.force = true;
  o.people_dir = people_dir;
  o.command_line = "dynorb bench (suite " + options.suite + "): preset " + o.preset + " seed " +
                   std::to_string(o.seed) + " frames " + std::to_string(o.frames) +
                   (o.static_twin ? " static twin" : "");
  o.Validate();
  if (!options.quiet) std::cerr << "bench: generating " << seq.dataset << "\n";
  const synth::SynthReport report = synth::Synthesize(o);
  for (const std::string& w : report.warnings) std::cerr << "bench: synth warning: " << w << "\n";
  fs::rename(temp, seq.dataset, ec);
  if (ec) throw InputError("cannot move " + temp + " to " + seq.dataset + ": " + ec.message());
}

// Adds the view-loss reference of a synthetic sequence (`dynamic`, with its static `twin`): the
// twin's images run in mode "semantic" with the dynamic sequence's ground-truth masks, so the
// people hide what they hide and nothing moving reaches the map. Its ATE over the twin's (plain)
// is the robustness ratio a perfect mask would give.
void AddViewLossReference(const BenchSequenceRun& dynamic, const BenchSequenceRun& twin,
                          const BenchSuite& suite, const std::vector<std::string>& registered,
                          int line, BenchPlan* plan) {
  if (std::find(registered.begin(), registered.end(), "semantic") == registered.end()) {
    plan->warnings.push_back("the view-loss reference of '" + dynamic.name +
                             "' needs mode 'semantic', not registered in this build: skipped");
    return;
  }
  bool has_plain = false;
  for (const BenchMode& m : suite.modes) {
    if (m.label == kViewLossLabel) {
      throw InputErrorAt(suite.file, m.line,
                         std::string("mode label '") + kViewLossLabel +
                             "' is reserved for the view-loss reference runs");
    }
    has_plain = has_plain || (m.name == "plain" && m.config.empty() && m.overlay.empty());
  }
  if (!has_plain) {
    throw InputErrorAt(suite.file, line,
                       "sequence '" + dynamic.name +
                           "': 'view_loss' needs the mode 'plain' (without a config) in the suite: "
                           "the reference is divided by the static twin's plain ATE");
  }
  if (!plan->view_loss_mode) {
    plan->view_loss_mode = std::make_unique<BenchMode>();
    plan->view_loss_mode->name = "semantic";
    plan->view_loss_mode->label = kViewLossLabel;
  }
  BenchSequenceRun ref = twin;
  ref.name = dynamic.name + kViewLossSuffix;
  ref.twin_of.clear();
  ref.twin = false;
  ref.view_loss_of = dynamic.name;
  ref.masks_dataset = dynamic.dataset;
  // The twin's own config (the sequence's `config:`, else its camera.yaml) plus the masks.
  ref.view_loss_base_config =
      twin.config.empty() ? (fs::path(twin.dataset) / "camera.yaml").string() : twin.config;
  ref.config = fs::path(dynamic.dataset).string() + "_viewloss.yaml";
  plan->sequences.push_back(ref);
}

// The view-loss reference's config: the twin's config, plus a `semantic` section reading the
// dynamic sequence's masks (absolute path). Written atomically before every bench run.
void WriteViewLossConfig(const BenchSequenceRun& ref) {
  std::ifstream in(ref.view_loss_base_config);
  if (!in) throw InputError("cannot read " + ref.view_loss_base_config);
  std::stringstream text;
  text << in.rdbuf();
  // A JSON string is a valid YAML double-quoted scalar: any folder name survives.
  const std::string list =
      nlohmann::json(
          fs::absolute(fs::path(ref.masks_dataset) / "masks.txt").lexically_normal().string())
          .dump();
  WriteFileAtomically(
      ref.config, text.str() +
                      "\n# dynorb bench: view-loss reference (the twin's images, the "
                      "masks of " +
                      ref.view_loss_of + ")\nsemantic:\n  source: masks\n  list: " + list + "\n");
}

// What a finished run was made from, kept next to its stats.json (kRequestFile): a run is resumed
// only when it equals the new request's. The files it read count by their contents (the hashes
// are compared within one build only: resuming also needs the same build id).
constexpr const char* kRequestFile = "bench_request.json";

std::string ContentHash(const std::string& path) {
  if (path.empty()) return "";
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return std::to_string(std::hash<std::string>()(text.str()));
}

nlohmann::json RequestFingerprint(const RunRequest& r) {
  std::vector<std::string> overlays;
  for (const std::string& o : r.config_overlays)
    overlays.push_back(SamePath(o) + "#" + ContentHash(o));
  const std::string config =
      r.config.empty() ? (fs::path(r.dataset) / "camera.yaml").string() : r.config;
  return {{"dataset", SamePath(r.dataset)},
          {"scene", ContentHash((fs::path(r.dataset) / "scene.yaml").string())},
          {"config", SamePath(config) + "#" + ContentHash(config)},
          {"overlays", overlays},
          {"mode", r.mode},
          {"run_mode", r.run_mode},
          {"seed", r.seed},
          {"frames", r.frames},
          {"models", SamePath(r.models)},
          {"pipeline", r.pipeline},
          {"pipeline_depth", r.pipeline_depth},
          {"front_end_threads", r.front_end_threads},
          {"preload", r.preload},
          {"save_map", r.save_map}};
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) return nullptr;
  return nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
}

nlohmann::json SuiteJson(const BenchPlan& plan, const std::vector<uint64_t>& seeds) {
  nlohmann::json j;
  j["name"] = plan.suite.name;
  j["file"] = plan.suite.file;
  j["description"] = plan.suite.description;
  j["seeds"] = seeds;
  j["run_mode"] = plan.suite.run_mode;
  j["pipeline"] = plan.suite.pipeline;
  j["pipeline_depth"] = plan.suite.pipeline_depth;
  j["front_end_threads"] = plan.suite.front_end_threads;
  j["preload"] = plan.suite.preload;
  j["save_map"] = plan.suite.save_map;
  j["sequences"] = nlohmann::json::array();
  for (const BenchSequenceRun& s : plan.sequences) {
    j["sequences"].push_back({{"name", s.name},
                              {"dataset", s.dataset},
                              {"tum_name", s.tum_name},
                              {"twin_of", s.twin_of},
                              {"view_loss_of", s.view_loss_of},
                              {"synthetic", s.synthetic},
                              {"preset", s.synthetic ? s.synth.preset : ""}});
  }
  j["modes"] = nlohmann::json::array();
  for (const BenchMode& m : plan.suite.modes) {
    j["modes"].push_back(
        {{"label", m.label}, {"name", m.name}, {"config", m.config}, {"overlay", m.overlay}});
  }
  if (plan.view_loss_mode) {
    j["modes"].push_back({{"label", plan.view_loss_mode->label},
                          {"name", plan.view_loss_mode->name},
                          {"config", ""},
                          {"view_loss", true}});
  }
  return j;
}

}  // namespace

BenchPlan PlanBench(const BenchOptions& options) {
  BenchPlan plan;
  plan.suite = LoadBenchSuite(options.suite);
  if (const std::string people = SynthPeopleDir(options);
      !people.empty() && !fs::is_directory(people))
    throw InputError("people directory not found: " + people +
                     " (--people DIR, auto or procedural)");
  BenchSuite& suite = plan.suite;
  const std::vector<std::string> registered = RunModeNames();
  std::vector<BenchMode> modes;
  for (const BenchMode& m : suite.modes) {
    if (std::find(registered.begin(), registered.end(), m.name) == registered.end()) {
      if (m.optional) {
        plan.warnings.push_back("mode '" + m.name + "' is not registered in this build (modes: " +
                                Join(registered) + "): skipped");
        continue;
      }
      throw InputErrorAt(
          suite.file, m.line,
          "unknown mode '" + m.name + "' (modes of this dynorb build: " + Join(registered) + ")");
    }
    if (!m.config.empty() && !fs::is_regular_file(m.config)) {
      throw InputErrorAt(suite.file, m.line,
                         "config file of mode '" + m.label + "' not found: " + m.config);
    }
    if (!m.overlay.empty() && !fs::is_regular_file(m.overlay)) {
      throw InputErrorAt(suite.file, m.line,
                         "overlay file of mode '" + m.label + "' not found: " + m.overlay);
    }
    // Their keys and values now, not after the sequences were generated.
    std::vector<std::string> files;
    for (const std::string& file : {m.config, m.overlay})
      if (!file.empty()) files.push_back(file);
    if (!files.empty()) CheckRunConfigFiles(m.name, files);
    modes.push_back(m);
  }
  if (modes.empty())
    throw InputError(suite.file + ": none of the suite's modes is registered in this build");
  plan.suite.modes = modes;
  const fs::path cache = fs::path(options.out) / "cache";
  for (const BenchSequence& s : suite.sequences) {
    BenchSequenceRun run;
    run.name = s.name;
    run.config = s.config;
    run.frames = s.frames;
    run.tum_name = s.tum_name;
    run.synthetic = s.synthetic;
    run.synth = s.synth;
    if (!s.config.empty() && !fs::is_regular_file(s.config)) {
      throw InputErrorAt(suite.file, s.line,
                         "config file of sequence '" + s.name + "' not found: " + s.config);
    }
    if (!s.config.empty()) CheckRunConfigFiles("plain", {s.config});
    if (s.synthetic) {
      if (!synth::FindPreset(s.synth.preset)) {
        throw InputErrorAt(suite.file, s.line,
                           "unknown synthetic preset '" + s.synth.preset +
                               "' (presets: " + synth::PresetNames() + ")");
      }
      run.dataset = (cache / CacheName(s.synth, false)).string();
      plan.sequences.push_back(run);
      if (s.synth.static_twin) {
        BenchSequenceRun twin = run;
        twin.name = s.name + "_twin";
        twin.twin = true;
        twin.twin_of = s.name;
        twin.tum_name.clear();
        twin.dataset = (cache / CacheName(s.synth, true)).string();
        plan.sequences.push_back(twin);
        if (s.synth.view_loss) AddViewLossReference(run, twin, suite, registered, s.line, &plan);
      }
      continue;
    }
    fs::path folder = s.path;
    if (folder.is_relative()) {
      folder = options.dataset_root.empty() ? fs::path(suite.file).parent_path() / folder
                                            : fs::path(options.dataset_root) / folder;
    }
    run.dataset = folder.lexically_normal().string();
    const bool present = fs::exists(folder / "rgb.txt") || fs::exists(folder / "associations.txt");
    if (!present) {
      const std::string message =
          "dataset of sequence '" + s.name + "' not found: " + run.dataset +
          (options.dataset_root.empty() ? " (pass --dataset-root DIR)" : "");
      if (!options.skip_missing)
        throw InputErrorAt(suite.file, s.line, message + " (or --skip-missing)");
      plan.warnings.push_back(message + ": skipped");
      continue;
    }
    if (s.config.empty() && !fs::exists(folder / "camera.yaml") &&
        !BuiltInConfigForDataset(run.dataset)) {
      throw InputErrorAt(suite.file, s.line,
                         "sequence '" + s.name +
                             "' has no camera.yaml and its folder is not named like a TUM "
                             "sequence: give 'config:' (e.g. config/tum_fr3.yaml)");
    }
    plan.sequences.push_back(run);
  }
  if (plan.sequences.empty()) throw InputError(suite.file + ": no sequence to run (all skipped)");
  const std::vector<uint64_t> seeds = suite.RunSeeds(options.repeats);
  for (const BenchSequenceRun& seq : plan.sequences) {
    std::vector<const BenchMode*> seq_modes;
    if (seq.view_loss_of.empty()) {
      for (const BenchMode& mode : suite.modes) seq_modes.push_back(&mode);
    } else {
      seq_modes.push_back(plan.view_loss_mode.get());
    }
    for (const BenchMode* mode_ptr : seq_modes) {
      const BenchMode& mode = *mode_ptr;
      for (size_t k = 0; k < seeds.size(); ++k) {
        BenchRun run;
        run.sequence = &seq;
        run.mode = &mode;
        run.seed = seeds[k];
        run.repeat = static_cast<int>(k);
        run.out_dir = (fs::path(options.out) / "runs" / seq.name / mode.label /
                       ("seed" + std::to_string(seeds[k])))
                          .string();
        plan.runs.push_back(run);
      }
    }
  }
  return plan;
}

nlohmann::json RunBench(const BenchOptions& options, const BenchPlan& plan) {
  const fs::path out(options.out);
  std::error_code ec;
  fs::create_directories(out / "plots", ec);
  if (!fs::is_directory(out / "plots"))
    throw InputError("cannot create output folder " + options.out);
  for (const std::string& w : plan.warnings) std::cerr << "bench: warning: " << w << "\n";
  for (const BenchSequenceRun& seq : plan.sequences) {
    if (seq.synthetic && seq.view_loss_of.empty()) EnsureSynthetic(seq, options);
  }
  for (const BenchSequenceRun& seq : plan.sequences) {
    if (!seq.view_loss_of.empty()) WriteViewLossConfig(seq);
  }

  const std::vector<uint64_t> seeds = plan.suite.RunSeeds(options.repeats);
  nlohmann::json results;
  results["format"] = "dynorb-bench-results/1";
  results["generated_utc"] = UtcNow();
  results["suite"] = SuiteJson(plan, seeds);
  results["runs"] = nlohmann::json::array();
  const std::string results_path = (out / "results.json").string();

  int done = 0, skipped = 0, failed = 0;
  ProgressBar progress("runs", static_cast<int>(plan.runs.size()));
  const auto start = std::chrono::steady_clock::now();
  for (const BenchRun& run : plan.runs) {
    const BenchSequenceRun& seq = *run.sequence;
    const std::string stats_path = (fs::path(run.out_dir) / "stats.json").string();
    const std::string key = seq.name + "__" + run.mode->label;
    nlohmann::json entry = {
        {"sequence", seq.name},        {"mode", run.mode->label},
        {"mode_name", run.mode->name}, {"seed", run.seed},
        {"repeat", run.repeat},        {"dir", fs::relative(run.out_dir, out).string()}};
    RunRequest request;
    request.dataset = seq.dataset;
    request.config = run.mode->config.empty() ? seq.config : run.mode->config;
    if (!run.mode->overlay.empty()) request.config_overlays = {run.mode->overlay};
    request.out = run.out_dir;
    request.mode = run.mode->name;
    request.run_mode = plan.suite.run_mode;
    request.pipeline = plan.suite.pipeline;
    request.pipeline_depth = plan.suite.pipeline_depth;
    request.front_end_threads = plan.suite.front_end_threads;
    request.preload = plan.suite.preload;
    request.save_map = plan.suite.save_map;
    request.seed = run.seed;
    request.frames = seq.frames;
    request.models = options.models;
    request.quiet = true;
    const std::string request_path = (fs::path(run.out_dir) / kRequestFile).string();
    const nlohmann::json fingerprint = RequestFingerprint(request);
    // Resume only results of this very executable made from this very request (and with map.ply
    // when the suite asks for it); others (or an unreadable stats.json) are run again.
    nlohmann::json previous = ReadJson(stats_path);
    const auto id = previous.is_object() ? previous.find("build_id") : previous.end();
    const bool same_build = BuildId() != kUnknownBuildId && previous.is_object() && id != previous.end() &&
                            id->is_string() && id->get<std::string>() == BuildId();
    const bool complete = !plan.suite.save_map || fs::exists(fs::path(run.out_dir) / "map.ply");
    const bool resume = same_build && complete && ReadJson(request_path) == fingerprint;
    // A run that is (re)done redraws its pictures; a resumed one draws only a missing trajectory
    // plot or map picture (the keypoint strip needs the overlays of a run that is done).
    const bool want_strip = options.plots && run.repeat == 0 && !resume;
    if (resume) {
      entry["status"] = "ok";
      entry["resumed"] = true;
      entry["stats"] = std::move(previous);
      ++skipped;
    } else {
      // A redone run's old pictures go first (with --no-plots too): if no new ones are drawn, the
      // report shows none rather than another build's.
      if (run.repeat == 0) {
        for (const char* suffix : {".png", ".svg", "_map.png", "_keypoints.png"})
          fs::remove(out / "plots" / (key + suffix), ec);
      }
      fs::remove(request_path, ec);  // Written again once this run is complete.
      if (want_strip) {
        // Overlays of a few frames only: drawing them is part of the timed filter stage.
        request.overlays = (fs::path(run.out_dir) / "overlays").string();
        request.overlay_every = kStripOverlayEvery;
      }
      try {
        entry["stats"] = RunPipeline(request);
        WriteFileAtomically(request_path, fingerprint.dump(1) + "\n");
        entry["status"] = "ok";
        for (const auto& warning : entry["stats"].value("warnings", nlohmann::json::array())) {
          std::cerr << "\nbench: run " << key << " seed " << run.seed
                    << ": warning: " << warning.get<std::string>() << "\n";
        }
      } catch (const std::exception& e) {
        entry["status"] = "failed";
        entry["error"] = e.what();
        ++failed;
        std::cerr << "\nbench: run " << key << " seed " << run.seed << " failed: " << e.what()
                  << "\n";
      }
    }
    if (options.plots && run.repeat == 0 && entry["status"] == "ok") {
      const std::string stem = (out / "plots" / key).string();
      if (!resume || !fs::exists(stem + ".png"))
        WriteTrajectoryPlot(seq.dataset, run.out_dir, stem, seq.name + " / " + run.mode->label);
      const std::string map_view = (out / "plots" / (key + "_map.png")).string();
      if (plan.suite.save_map && (!resume || !fs::exists(map_view)))
        WriteMapView(run.out_dir, map_view, seq.name + " / " + run.mode->label);
      const fs::path overlays = fs::path(run.out_dir) / "overlays";
      if (fs::is_directory(overlays)) {
        WriteKeypointStrip(overlays.string(), (out / "plots" / (key + "_keypoints.png")).string());
        fs::remove_all(overlays, ec);
      }
    }
    results["runs"].push_back(entry);
    WriteFileAtomically(results_path,
                        results.dump(1) + "\n");  // partial results survive an interrupt
    ++done;
    if (!options.quiet) {
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      char extra[160];
      std::snprintf(extra, sizeof(extra), "%.0f s, %d resumed, %d failed; last: %s seed %llu", s,
                    skipped, failed, key.c_str(), static_cast<unsigned long long>(run.seed));
      progress.Update(done, extra);
    }
  }
  results["summary"] = {{"runs", plan.runs.size()}, {"resumed", skipped}, {"failed", failed}};
  WriteFileAtomically(results_path, results.dump(1) + "\n");
  return results;
}

}  // namespace dynorb
