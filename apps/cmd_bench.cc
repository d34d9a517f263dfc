// `dynorb bench`: runs a benchmark suite (sequences x modes x seeds) and writes results.json,
// report.md, report.html and plots; `--report DIR` re-renders the reports of a stored
// results.json. See docs/benchmark.md.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <vector>

#include "bench_report.h"
#include "bench_runner.h"
#include "command_registry.h"
#include "dynorb/core/error.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;

struct BenchCli {
  BenchOptions options;
  std::string report_dir;
  std::string published;
  bool list = false;
  bool no_plots = false;
};

// --published, else <suite folder>/../published_results.json, else bench/published_results.json.
// The published numbers' shape: {"systems": [{"system": "...", "ate_rmse_m": {"seq": number, ...},
// "source"/"note": strings, "verified": bool}, ...]} (bench/published_results.json).
nlohmann::json CheckPublished(nlohmann::json published, const std::string& path) {
  auto fail = [&](const std::string& what) {
    throw InputError(path + ": " + what + " (see bench/published_results.json for the format)");
  };
  if (!published.is_object() || !published.contains("systems") || !published["systems"].is_array())
    fail("expected an object with an array 'systems'");
  for (const nlohmann::json& sys : published["systems"]) {
    if (!sys.is_object()) fail("every entry of 'systems' must be an object");
    for (const char* key : {"system", "source", "note"}) {
      if (sys.contains(key) && !sys[key].is_string())
        fail(std::string("'") + key + "' must be a string");
    }
    if (sys.contains("verified") && !sys["verified"].is_boolean())
      fail("'verified' must be true or false");
    if (!sys.contains("ate_rmse_m") || !sys["ate_rmse_m"].is_object())
      fail("every system needs an object 'ate_rmse_m'");
    for (const auto& [sequence, value] : sys["ate_rmse_m"].items()) {
      if (!value.is_number()) fail("'ate_rmse_m' of '" + sequence + "' must be a number");
    }
  }
  return published;
}

// What the report reads without looking: {"suite": {"sequences": [{"name"}], "modes": [{"label"}],
// "seeds": [...]}, "runs": [{"sequence", "mode", "seed", "stats": {}}]}. (Const operator[] on a
// missing key is undefined behaviour in nlohmann::json, so a hand-edited results.json is checked.)
void CheckResultsShape(const nlohmann::json& results, const std::string& path) {
  auto fail = [&](const std::string& what) {
    throw InputError(path + ": " + what + "; results.json is written by `dynorb bench`");
  };
  auto require = [&](const nlohmann::json& object, const char* key, auto is_kind,
                     const char* kind) {
    if (!object.is_object() || !object.contains(key) || !is_kind(object[key]))
      fail(std::string("expected '") + key + "' (" + kind + ")");
  };
  const auto is_object = [](const nlohmann::json& j) { return j.is_object(); };
  const auto is_array = [](const nlohmann::json& j) { return j.is_array(); };
  const auto is_string = [](const nlohmann::json& j) { return j.is_string(); };
  const auto is_unsigned = [](const nlohmann::json& j) { return j.is_number_unsigned(); };
  if (!results.is_object() || !results.contains("format") ||
      results["format"] != "dynorb-bench-results/1")
    throw InputError(path +
                     ": not a dynorb bench results.json (format dynorb-bench-results/1 expected)");
  require(results, "suite", is_object, "an object");
  require(results, "runs", is_array, "an array");
  const nlohmann::json& suite = results["suite"];
  require(suite, "sequences", is_array, "an array");
  require(suite, "modes", is_array, "an array");
  require(suite, "seeds", is_array, "an array");
  for (const nlohmann::json& s : suite["sequences"]) require(s, "name", is_string, "a string");
  for (const nlohmann::json& m : suite["modes"]) require(m, "label", is_string, "a string");
  for (const nlohmann::json& run : results["runs"]) {
    require(run, "sequence", is_string, "a string");
    require(run, "mode", is_string, "a string");
    require(run, "seed", is_unsigned, "a non-negative integer");
    if (run.value("status", "") == "ok") require(run, "stats", is_object, "an object");
  }
}

nlohmann::json LoadPublished(const std::string& explicit_path, const std::string& suite_file) {
  if (!explicit_path.empty()) return CheckPublished(ReadBenchJson(explicit_path), explicit_path);
  std::vector<fs::path> candidates;
  if (!suite_file.empty())
    candidates.push_back(fs::path(suite_file).parent_path() / ".." / "published_results.json");
  candidates.push_back(fs::path("bench") / "published_results.json");
  for (const fs::path& candidate : candidates) {
    if (fs::is_regular_file(candidate)) {
      const std::string path = candidate.lexically_normal().string();
      return CheckPublished(ReadBenchJson(path), path);
    }
  }
  return nullptr;
}

void RunBenchCommand(BenchCli cli) {
  if (!cli.report_dir.empty()) {
    const std::string results_path = (fs::path(cli.report_dir) / "results.json").string();
    const nlohmann::json results = ReadBenchJson(results_path);
    // Valid JSON of the wrong shape (an edited or damaged file) is named, not left to
    // nlohmann's message alone.
    try {
      CheckResultsShape(results, results_path);
      const std::string suite_file = results["suite"].value("file", "");
      WriteBenchReport(results, LoadPublished(cli.published, suite_file), cli.report_dir);
    } catch (const nlohmann::json::exception& e) {
      throw InputError(results_path + " (or the published numbers' file): unexpected content (" +
                       e.what() + "); results.json is written by `dynorb bench`");
    }
    std::cout << "wrote " << cli.report_dir << "/report.md and report.html\n";
    return;
  }
  if (cli.options.suite.empty() || cli.options.out.empty())
    throw InputError("bench needs --suite FILE and --out DIR (or --report DIR)");
  cli.options.plots = !cli.no_plots;
  const BenchPlan plan = PlanBench(cli.options);
  const nlohmann::json published =
      LoadPublished(cli.published, cli.options.suite);  // bad file: fail before running
  if (cli.list) {
    for (const BenchRun& run : plan.runs) {
      std::cout << run.sequence->name << "\t" << run.mode->label << "\tseed " << run.seed << "\t"
                << run.out_dir << (fs::exists(fs::path(run.out_dir) / "stats.json") ? "\tdone" : "")
                << "\n";
    }
    for (const std::string& w : plan.warnings) std::cerr << "bench: warning: " << w << "\n";
    return;
  }
  const nlohmann::json results = RunBench(cli.options, plan);
  try {
    WriteBenchReport(results, published, cli.options.out);
  } catch (const nlohmann::json::exception& e) {  // e.g. a resumed run's stats.json edited by hand
    throw InputError(cli.options.out +
                     "/results.json (from the runs' stats.json): unexpected "
                     "content (" +
                     std::string(e.what()) + "); delete the run's stats.json to run it again");
  }
  const nlohmann::json& summary = results["summary"];
  std::cout << "runs: " << summary["runs"] << " (" << summary["resumed"] << " resumed, "
            << summary["failed"] << " failed)\nwrote " << cli.options.out
            << "/{results.json,report.md,report.html,plots/}\n";
  if (summary["failed"].get<int>() > 0) {
    throw std::runtime_error(summary["failed"].dump() +
                             " run(s) failed (errors in results.json); run the same "
                             "command again to retry them");
  }
}

const bool kRegistered = RegisterCommand("bench", 30, [](CLI::App& app) {
  auto cli = std::make_shared<BenchCli>();
  CLI::App* cmd = app.add_subcommand(
      "bench",
      "Run a benchmark suite (sequences x modes x seeds): results.json, report.md/html with "
      "accuracy, robustness and "
      "speed tables, plots. Interrupted? Run the same command again: finished runs are kept.");
  cmd->add_option("--suite", cli->options.suite, "Suite YAML (e.g. bench/suites/quick.yaml)");
  cmd->add_option("--out", cli->options.out, "Output folder (created; reused to resume)");
  cmd->add_option("--repeats", cli->options.repeats,
                  "Runs per sequence and mode with seeds 1..N (overrides the suite)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option(
      "--dataset-root", cli->options.dataset_root,
      "Folder holding the suite's real sequences (e.g. the TUM rgbd_dataset_* folders)");
  cmd->add_flag("--skip-missing", cli->options.skip_missing,
                "Skip real sequences that are not there (warning)");
  cmd->add_flag("--no-plots", cli->no_plots, "No trajectory plots or keypoint strips");
  cmd->add_option(
      "--published", cli->published,
      "Published numbers (default: bench/published_results.json next to the suites folder)");
  cmd->add_option("--people", cli->options.people_dir,
                  "Synthetic sequences: people cut-outs folder or 'procedural' (default: "
                  "../shared/data/people if "
                  "present)");
  cmd->add_option("--models", cli->options.models, "Detector model folder (semantic modes)");
  cmd->add_flag("--list", cli->list,
                "Check the suite and print the runs (done ones marked) without running");
  cmd->add_flag("--quiet", cli->options.quiet, "No progress bar");
  cmd->add_option("--report", cli->report_dir,
                  "Only re-render DIR/report.{md,html} from DIR/results.json");
  cmd->callback([cli] { RunBenchCommand(*cli); });
});

}  // namespace
}  // namespace dynorb
