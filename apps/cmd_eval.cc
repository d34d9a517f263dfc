// `dynorb eval`: ATE / RPE / coverage of an estimated trajectory against ground truth (TUM format).
// Reads both files, evaluates (dynorb/eval), prints a table, optionally writes JSON and a plot.
// Output files are opened (validated) before the work and committed atomically at the end, so a
// failed run leaves no output file behind. Definitions: docs/evaluation.md.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <utility>

#include "command_registry.h"
#include "dynorb/core/error.h"
#include "dynorb/eval/evaluate.h"
#include "dynorb/eval/plot.h"
#include "dynorb/eval/report.h"
#include "dynorb/io/atomic_file.h"
#include "dynorb/io/trajectory_io.h"

namespace dynorb {
namespace {

struct EvalCliOptions {
  std::string gt_path;
  std::string est_path;
  std::string align = "se3";
  double max_diff_s = 0.02;
  double offset_s = 0.0;
  double rpe_delta_s = 1.0;
  std::string json_path;
  std::string plot_path;
};

// True when a and b name the same file: the same path once made absolute and normalised
// ("./r.txt", "d/../r.txt"), or, when both exist, the same file (a link, another spelling).
bool SameFile(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec_a, ec_b, ec;
  const fs::path normal_a = fs::absolute(a, ec_a).lexically_normal();
  const fs::path normal_b = fs::absolute(b, ec_b).lexically_normal();
  if (a == b || (!ec_a && !ec_b && normal_a == normal_b)) return true;
  return fs::equivalent(a, b, ec);  // false unless both exist
}

// An output that names an input would overwrite it: refused before anything is written.
void CheckOutputIsNotAnInput(const std::string& option, const std::string& output,
                             const EvalCliOptions& cli) {
  if (output.empty()) return;
  const std::pair<const char*, std::string> inputs[] = {{"--gt", cli.gt_path},
                                                        {"--est", cli.est_path}};
  for (const auto& [input_option, input] : inputs) {
    if (SameFile(output, input)) {
      throw InputError(option + " " + output + " names the same file as " + input_option + " " +
                       input + ": it would overwrite the input");
    }
  }
}

bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

void RunEval(const EvalCliOptions& cli) {
  EvalOptions options;
  options.alignment = ParseAlignmentMode(cli.align);
  options.association.max_diff_s = cli.max_diff_s;
  options.association.offset_s = cli.offset_s;
  options.rpe_delta_s = cli.rpe_delta_s;
  options.Validate();
  const bool plot_svg = EndsWith(cli.plot_path, ".svg");
  if (!cli.plot_path.empty() && !plot_svg && !EndsWith(cli.plot_path, ".png")) {
    throw InputError("--plot must name a .png or .svg file, got '" + cli.plot_path + "'");
  }
  if (!cli.json_path.empty() && !cli.plot_path.empty() && SameFile(cli.json_path, cli.plot_path))
    throw InputError("--json and --plot name the same file");
  CheckOutputIsNotAnInput("--json", cli.json_path, cli);
  CheckOutputIsNotAnInput("--plot", cli.plot_path, cli);

  // Open outputs first: an unwritable path fails before any work, and nothing is left behind.
  std::unique_ptr<AtomicFile> json_file, plot_file;
  if (!cli.json_path.empty()) json_file = std::make_unique<AtomicFile>(cli.json_path);
  if (!cli.plot_path.empty()) plot_file = std::make_unique<AtomicFile>(cli.plot_path);

  // Ground truth as TUM publishes it (fr3/walking_static repeats a stamp: the later pose wins).
  const Trajectory gt = ReadTumGroundTruth(cli.gt_path);
  const Trajectory est = ReadTumTrajectory(cli.est_path);
  const EvalResult result = EvaluateTrajectories(gt, est, options);
  const ReportInputs inputs{cli.gt_path, cli.est_path};

  if (json_file) json_file->stream() << FormatReportJson(result, inputs);
  if (plot_file) {
    const PlotCanvas canvas = LayoutEvalFigure(gt, est, result);
    if (plot_svg) {
      plot_file->stream() << RenderPlotSvg(canvas);
    } else {
      const std::vector<unsigned char> png = RenderPlotPng(canvas);
      if (png.empty()) throw InputError("PNG encoding failed for " + cli.plot_path);
      plot_file->stream().write(reinterpret_cast<const char*>(png.data()),
                                static_cast<std::streamsize>(png.size()));
    }
  }
  if (json_file) json_file->Commit();
  if (plot_file) plot_file->Commit();

  std::cout << FormatReportTable(result, inputs);
  if (json_file) std::cout << "json          " << cli.json_path << "\n";
  if (plot_file) std::cout << "plot          " << cli.plot_path << "\n";
  std::cout.flush();
}

const bool kRegistered = RegisterCommand("eval", 80, [](CLI::App& app) {
  auto opts = std::make_shared<EvalCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "eval",
      "Evaluate a trajectory against ground truth: ATE (TUM evaluate_ate.py), RPE (evaluate_rpe.py "
      "--fixed_delta, delta in seconds), coverage. Files in TUM format: 'timestamp tx ty tz qx qy "
      "qz qw'.");
  cmd->add_option("--gt", opts->gt_path, "ground-truth trajectory (TUM format)")->required();
  cmd->add_option("--est", opts->est_path, "estimated trajectory (TUM format)")->required();
  cmd->add_option(
         "--align", opts->align,
         "alignment before ATE: se3 (rigid, RGB-D/stereo), sim3 (with scale, monocular), none")
      ->capture_default_str();
  cmd->add_option("--max-diff", opts->max_diff_s,
                  "max |t_gt - (t_est + offset)| for associating poses, seconds")
      ->capture_default_str();
  cmd->add_option("--offset", opts->offset_s, "time offset added to estimate stamps, seconds")
      ->capture_default_str();
  cmd->add_option("--rpe-delta", opts->rpe_delta_s, "RPE pose-pair distance, seconds")
      ->capture_default_str();
  cmd->add_option("--json", opts->json_path, "write all results as JSON to this file");
  cmd->add_option("--plot", opts->plot_path,
                  "write a figure (top view, side view, error over time) to FILE.png or FILE.svg");
  cmd->callback([opts] { RunEval(*opts); });
});

}  // namespace
}  // namespace dynorb
