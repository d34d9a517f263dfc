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
nlohmann::json LoadPublished(const std::string& explicit_path, const std::string& suite_file) {
  if (!explicit_path.empty()) return ReadBenchJson(explicit_path);
  std::vector<fs::path> candidates;
  if (!suite_file.empty())
    candidates.push_back(fs::path(suite_file).parent_path() / ".." / "published_results.json");
  candidates.push_back(fs::path("bench") / "published_results.json");
  for (const fs::path& candidate : candidates) {
    if (fs::is_regular_file(candidate)) return ReadBenchJson(candidate.lexically_normal().string());
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
      const std::string suite_file = results.contains("suite") && results["suite"].is_object()
                                         ? results["suite"].value("file", "")
                                         : "";
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
  WriteBenchReport(results, published, cli.options.out);
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
