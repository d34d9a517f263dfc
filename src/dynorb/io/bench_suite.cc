#include "dynorb/io/bench_suite.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "dynorb/core/error.h"
#include "dynorb/io/frame_range.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;

class Parser {
 public:
  Parser(std::string source, std::string base_dir)
      : source_(std::move(source)), base_(std::move(base_dir)) {}

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& message) const {
    throw InputErrorAt(source_, node.Mark().line + 1, message);
  }

  // Checks that `map` is a mapping with only `allowed` keys (and no duplicates).
  void CheckKeys(const YAML::Node& map, const std::set<std::string>& allowed,
                 const std::string& what) const {
    if (!map.IsMap()) Fail(map, what + " must be a mapping");
    std::set<std::string> seen;
    for (const auto& kv : map) {
      // A key that is itself a mapping or a list (e.g. a stray ',' before a '{') has no name.
      if (!kv.first.IsScalar()) Fail(kv.first, "a key of " + what + " must be a plain name");
      const std::string key = kv.first.Scalar();
      if (!allowed.count(key)) {
        std::string list;
        for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
        Fail(kv.first, "unknown key '" + key + "' in " + what + " (allowed: " + list + ")");
      }
      if (!seen.insert(key).second) Fail(kv.first, "duplicate key '" + key + "'");
    }
  }

  template <typename T>
  T Get(const YAML::Node& node, const std::string& key, const std::string& type_name) const {
    if (!node.IsScalar()) Fail(node, "'" + key + "' expects " + type_name);
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      Fail(node, "'" + key + "' expects " + type_name + ", got '" + node.Scalar() + "'");
    }
  }

  std::string Str(const YAML::Node& node, const std::string& key) const {
    return Get<std::string>(node, key, "a string");
  }
  int PositiveInt(const YAML::Node& node, const std::string& key, int min) const {
    const long long v = Get<long long>(node, key, "an integer");
    if (v < min) Fail(node, "'" + key + "' must be >= " + std::to_string(min));
    if (v > 1000000) Fail(node, "'" + key + "' must be <= 1000000, got " + std::to_string(v));
    return static_cast<int>(v);
  }
  uint64_t Seed(const YAML::Node& node, const std::string& key) const {
    return Get<uint64_t>(node, key, "a non-negative integer");
  }
  bool Bool(const YAML::Node& node, const std::string& key) const {
    return Get<bool>(node, key, "true or false");
  }

  std::string Resolve(const std::string& path) const {
    if (path.empty() || fs::path(path).is_absolute()) return path;
    return (fs::path(base_) / path).lexically_normal().string();
  }

  void CheckName(const YAML::Node& node, const std::string& name) const {
    if (name.empty()) Fail(node, "empty name");
    // A name is a folder of --out: '.', '..' or a hidden name would write elsewhere or hide it.
    if (name.front() == '.') Fail(node, "name '" + name + "' may not start with '.'");
    for (char c : name) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') {
        Fail(node, "name '" + name + "' may only contain letters, digits, '_', '-' and '.'");
      }
    }
  }

  BenchSequence Sequence(const YAML::Node& node) const {
    CheckKeys(node, {"name", "path", "synthetic", "config", "frames", "tum_name"}, "a sequence");
    BenchSequence s;
    s.line = node.Mark().line + 1;
    if (!node["name"]) Fail(node, "sequence without 'name'");
    s.name = Str(node["name"], "name");
    CheckName(node["name"], s.name);
    if (node["path"] && node["synthetic"])
      Fail(node, "sequence '" + s.name + "' has both 'path' and 'synthetic'");
    if (!node["path"] && !node["synthetic"]) {
      Fail(node,
           "sequence '" + s.name + "' needs 'path' (TUM-format folder) or 'synthetic' (preset)");
    }
    if (node["path"]) s.path = Str(node["path"], "path");
    if (const YAML::Node syn = node["synthetic"]) {
      CheckKeys(syn, {"preset", "seed", "frames", "static_twin", "view_loss"}, "'synthetic'");
      s.synthetic = true;
      if (!syn["preset"]) Fail(syn, "'synthetic' needs a 'preset'");
      s.synth.preset = Str(syn["preset"], "preset");
      if (syn["seed"]) s.synth.seed = Seed(syn["seed"], "seed");
      if (syn["frames"]) s.synth.frames = PositiveInt(syn["frames"], "frames", 1);
      if (syn["static_twin"]) s.synth.static_twin = Bool(syn["static_twin"], "static_twin");
      if (syn["view_loss"]) s.synth.view_loss = Bool(syn["view_loss"], "view_loss");
      if (s.synth.view_loss && !s.synth.static_twin) {
        Fail(syn["view_loss"], "'view_loss' needs 'static_twin: true' (it runs the twin's images)");
      }
    }
    if (node["config"]) s.config = Resolve(Str(node["config"], "config"));
    if (node["frames"]) {
      s.frames = Str(node["frames"], "frames");
      try {
        ParseFrameRange(s.frames, "'frames'");  // The sequence's length is known only at run time.
      } catch (const InputError& e) {
        Fail(node["frames"], e.what());
      }
    }
    if (node["tum_name"]) s.tum_name = Str(node["tum_name"], "tum_name");
    return s;
  }

  BenchMode Mode(const YAML::Node& node) const {
    BenchMode m;
    m.line = node.Mark().line + 1;
    if (node.IsScalar()) {
      m.name = Str(node, "modes");
    } else {
      CheckKeys(node, {"name", "config", "overlay", "label", "optional"}, "a mode");
      if (!node["name"]) Fail(node, "mode without 'name'");
      m.name = Str(node["name"], "name");
      if (node["config"]) m.config = Resolve(Str(node["config"], "config"));
      if (node["overlay"]) m.overlay = Resolve(Str(node["overlay"], "overlay"));
      if (node["optional"]) m.optional = Bool(node["optional"], "optional");
      if (node["label"]) {
        m.label = Str(node["label"], "label");
        CheckName(node["label"], m.label);
      }
    }
    if (m.label.empty()) {
      m.label = m.name;
      if (!m.config.empty()) m.label += "-" + fs::path(m.config).stem().string();
      if (!m.overlay.empty()) m.label += "-" + fs::path(m.overlay).stem().string();
    }
    return m;
  }

  BenchSuite Suite(const YAML::Node& root) const {
    if (!root || root.IsNull()) throw InputError(source_ + ": empty suite file");
    CheckKeys(root,
              {"name", "description", "repeats", "seeds", "run_mode", "pipeline", "pipeline_depth",
               "front_end_threads", "preload", "save_map", "sequences", "modes"},
              "the suite");
    BenchSuite suite;
    suite.file = source_;
    suite.name = root["name"] ? Str(root["name"], "name") : fs::path(source_).stem().string();
    if (root["description"]) suite.description = Str(root["description"], "description");
    if (root["repeats"]) suite.repeats = PositiveInt(root["repeats"], "repeats", 1);
    if (const YAML::Node seeds = root["seeds"]) {
      if (!seeds.IsSequence() || seeds.size() == 0)
        Fail(seeds, "'seeds' expects a non-empty list of integers");
      for (const auto& s : seeds) {
        const uint64_t seed = Seed(s, "seeds");
        // Two runs with one seed would share one output folder.
        if (std::find(suite.seeds.begin(), suite.seeds.end(), seed) != suite.seeds.end())
          Fail(s, "seed " + std::to_string(seed) + " is listed twice in 'seeds'");
        suite.seeds.push_back(seed);
      }
    }
    if (root["run_mode"]) {
      suite.run_mode = Str(root["run_mode"], "run_mode");
      if (suite.run_mode != "sequential" && suite.run_mode != "parallel") {
        Fail(root["run_mode"],
             "'run_mode' must be sequential or parallel, got '" + suite.run_mode + "'");
      }
    }
    if (root["pipeline"]) suite.pipeline = Bool(root["pipeline"], "pipeline");
    if (root["pipeline_depth"]) {
      suite.pipeline_depth = PositiveInt(root["pipeline_depth"], "pipeline_depth", 1);
      if (suite.pipeline_depth > kMaxPipelineDepth) {
        Fail(root["pipeline_depth"], "'pipeline_depth' must be 1.." + std::to_string(kMaxPipelineDepth));
      }
    }
    if (root["front_end_threads"]) {
      suite.front_end_threads = PositiveInt(root["front_end_threads"], "front_end_threads", 0);
      if (suite.front_end_threads > 2)
        Fail(root["front_end_threads"], "'front_end_threads' must be 0 (auto), 1 or 2");
    }
    if (root["preload"]) suite.preload = Bool(root["preload"], "preload");
    if (root["save_map"]) suite.save_map = Bool(root["save_map"], "save_map");
    const YAML::Node seqs = root["sequences"];
    if (!seqs || !seqs.IsSequence() || seqs.size() == 0) {
      Fail(seqs ? seqs : root, "the suite needs a non-empty list 'sequences'");
    }
    std::set<std::string> names;
    for (const auto& node : seqs) {
      suite.sequences.push_back(Sequence(node));
      const std::string& name = suite.sequences.back().name;
      if (!names.insert(name).second || !names.insert(name + "_twin").second ||
          !names.insert(name + kViewLossSuffix).second) {
        Fail(node, "duplicate sequence name '" + name + "'");
      }
    }
    const YAML::Node modes = root["modes"];
    if (!modes || !modes.IsSequence() || modes.size() == 0)
      Fail(modes ? modes : root, "the suite needs a non-empty list 'modes'");
    std::set<std::string> labels;
    for (const auto& node : modes) {
      suite.modes.push_back(Mode(node));
      if (!labels.insert(suite.modes.back().label).second) {
        Fail(node,
             "duplicate mode '" + suite.modes.back().label + "' (give one of them a 'label')");
      }
    }
    return suite;
  }

 private:
  std::string source_, base_;
};

}  // namespace

std::vector<uint64_t> BenchSuite::RunSeeds(int repeats_override) const {
  if (repeats_override <= 0 && !seeds.empty()) return seeds;
  const int n = repeats_override > 0 ? repeats_override : repeats;
  std::vector<uint64_t> out;
  for (int i = 1; i <= n; ++i) out.push_back(static_cast<uint64_t>(i));
  return out;
}

BenchSuite ParseBenchSuite(const std::string& yaml_text, const std::string& source_name,
                           const std::string& base_dir) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw InputErrorAt(source_name, e.mark.line + 1, "invalid YAML: " + e.msg);
  }
  return Parser(source_name, base_dir).Suite(root);
}

BenchSuite LoadBenchSuite(const std::string& path) {
  std::ifstream in(path);
  if (!fs::is_regular_file(path) || !in) throw InputError("suite file not found: " + path);
  std::stringstream text;
  text << in.rdbuf();
  return ParseBenchSuite(text.str(), path, fs::path(path).parent_path().string());
}

}  // namespace dynorb
