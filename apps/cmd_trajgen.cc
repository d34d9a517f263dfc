// `dynorb trajgen`: writes a synthetic ground-truth / estimate trajectory pair (TUM format) for
// trying out `dynorb eval`: groundtruth.txt (smooth hand-held-like path) and estimate.txt (the
// same path in another world frame, with drift, noise, optional scale, jittered stamps and a few
// dropped frames). Deterministic for a seed. See dynorb/eval/trajectory_generator.h.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "command_registry.h"
#include "dynorb/core/error.h"
#include "dynorb/eval/trajectory_generator.h"
#include "dynorb/io/atomic_file.h"
#include "dynorb/io/trajectory_io.h"

namespace dynorb {
namespace {

struct TrajgenCliOptions {
  std::string out_dir;
  TrajectoryPairOptions pair;
};

void RunTrajgen(const TrajgenCliOptions& cli) {
  cli.pair.Validate();
  namespace fs = std::filesystem;
  OutputFolder out_folder(cli.out_dir, "output directory");  // Removed again if the command fails.
  const TrajectoryPair pair = GenerateTrajectoryPair(cli.pair);
  const std::string gt_path = (fs::path(cli.out_dir) / "groundtruth.txt").string();
  const std::string est_path = (fs::path(cli.out_dir) / "estimate.txt").string();
  CheckOutputTargets({gt_path, est_path});  // neither is written when the other cannot be
  WriteTumTrajectory(gt_path, pair.groundtruth);
  WriteTumTrajectory(est_path, pair.estimate);
  out_folder.Keep();
  std::cout << "wrote " << gt_path << " (" << pair.groundtruth.size() << " poses)\n"
            << "wrote " << est_path << " (" << pair.estimate.size() << " poses, "
            << pair.groundtruth.size() - pair.estimate.size() << " dropped)\n";
}

const bool kRegistered = RegisterCommand("trajgen", 85, [](CLI::App& app) {
  auto opts = std::make_shared<TrajgenCliOptions>();
  CLI::App* cmd = app.add_subcommand("trajgen",
                                     "Write a synthetic groundtruth.txt / estimate.txt pair (TUM "
                                     "format) for trying `dynorb eval`");
  TrajectoryPairOptions& p = opts->pair;
  cmd->add_option("--out", opts->out_dir, "output directory (created if missing)")->required();
  cmd->add_option("--seed", p.seed, "random seed")->check(NonNegativeInteger())->capture_default_str();
  cmd->add_option("--duration-s", p.duration_s, "trajectory length, seconds")
      ->capture_default_str();
  cmd->add_option("--rate-hz", p.rate_hz, "pose rate, Hz")->capture_default_str();
  cmd->add_option("--noise-m", p.noise_m,
                  "estimate position noise sigma per axis, m (rotation: rad)")
      ->capture_default_str();
  cmd->add_option("--drift-m-per-s", p.drift_m_per_s, "estimate linear drift, m/s")
      ->capture_default_str();
  cmd->add_option("--scale", p.scale, "estimate scale (e.g. 0.5 for a monocular-like estimate)")
      ->capture_default_str();
  cmd->add_option("--drop-fraction", p.drop_fraction, "fraction of estimate frames dropped")
      ->capture_default_str();
  cmd->callback([opts] { RunTrajgen(*opts); });
});

}  // namespace
}  // namespace dynorb
