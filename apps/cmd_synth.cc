// `dynorb synth`: generate a synthetic dynamic RGB-D sequence in the TUM layout (office scene,
// walking people, pushed objects, Kinect-like sensor), see docs/synthetic.md.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "command_registry.h"
#include "dynorb/core/error.h"
#include "dynorb/synth/camera_motion.h"
#include "dynorb/synth/synthesizer.h"

namespace dynorb {
namespace {

constexpr const char* kDefaultPeopleDir = "../shared/data/people";

struct SynthCli {
  synth::SynthOptions options;
  std::string people = "auto";
  std::string textures;
  int frames = 0;
  bool no_noise = false;
};

void PrintProgress(int done, int total, double seconds) {
  static int last_percent = -1;
  const bool tty = isatty(fileno(stderr));
  const int percent = total > 0 ? 100 * done / total : 100;
  if (!tty && percent / 10 == last_percent / 10 && done != total) return;
  last_percent = percent;
  const int width = 30, filled = width * percent / 100;
  const double fps = seconds > 0 ? done / seconds : 0.0;
  std::fprintf(stderr, "%s[%s%s] %d/%d frames %5.1f fps%s", tty ? "\r" : "",
               std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), done,
               total, fps, tty ? "" : "\n");
  if (tty && done == total) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

void RunSynth(SynthCli cli) {
  synth::SynthOptions& o = cli.options;
  o.noise = !cli.no_noise;
  o.frames = cli.frames;
  if (!cli.textures.empty()) {
    o.texture_dir = cli.textures;
    o.texture_dir_explicit = true;
  }
  if (cli.people == "auto") {
    o.people_dir = std::filesystem::is_directory(kDefaultPeopleDir) ? kDefaultPeopleDir : "";
  } else if (cli.people != "procedural") {
    o.people_dir = cli.people;
  }
  std::string cmd = "dynorb synth --preset " + o.preset + " --seed " + std::to_string(o.seed) +
                    " --out " + o.out_dir;
  if (cli.frames > 0) cmd += " --frames " + std::to_string(cli.frames);
  if (o.static_twin) cmd += " --static-twin";
  cmd += " --people " + (o.people_dir.empty() ? std::string("procedural") : o.people_dir);
  if (o.num_people > 0) cmd += " --num-people " + std::to_string(o.num_people);
  if (cli.no_noise) cmd += " --no-noise";
  if (!cli.textures.empty()) cmd += " --textures " + cli.textures;
  if (!o.trajectory_file.empty()) cmd += " --trajectory " + o.trajectory_file;
  if (o.supersample != 2) cmd += " --supersample " + std::to_string(o.supersample);
  o.command_line = cmd;
  o.Validate();

  const auto start = std::chrono::steady_clock::now();
  const synth::SynthReport report = synth::Synthesize(o, [&](int done, int total) {
    PrintProgress(done, total,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  });
  for (const std::string& w : report.warnings) std::cerr << "dynorb synth: warning: " << w << "\n";
  std::cout << "wrote " << report.frames << " frames to " << o.out_dir << " in " << report.seconds
            << " s (" << report.frames / std::max(1e-9, report.seconds) << " frames/s)\n";
}

const bool kRegistered = RegisterCommand("synth", 15, [](CLI::App& app) {
  auto cli = std::make_shared<SynthCli>();
  CLI::App* cmd = app.add_subcommand("synth",
                                     "Generate a synthetic dynamic RGB-D sequence (TUM layout: "
                                     "rgb/, depth/, masks/, rgb.txt, depth.txt, "
                                     "groundtruth.txt, camera.yaml, scene.yaml): an office with "
                                     "walking people and moved objects seen by a "
                                     "hand-held Kinect-like camera.");
  cmd->add_option("--preset", cli->options.preset,
                  "camera motion and people: " + synth::PresetNames())
      ->capture_default_str();
  cmd->add_option("--seed", cli->options.seed, "random seed (layout details, paths, noise)")
      ->check(NonNegativeInteger())
      ->capture_default_str();
  cmd->add_option("--out", cli->options.out_dir, "output directory (must be empty unless --force)")
      ->required();
  cmd->add_option("--frames", cli->frames,
                  "number of frames (default: the preset's duration at 30 Hz)");
  cmd->add_flag("--static-twin", cli->options.static_twin,
                "the same sequence with every moving object removed (for ATE ratios)");
  cmd->add_option("--people", cli->people,
                  "directory of RGBA *.png cut-outs of people, or 'procedural' (default: "
                  "../shared/data/people "
                  "if present, else procedural figures)")
      ->capture_default_str();
  cmd->add_option("--num-people", cli->options.num_people, "number of people 1..3 (default 2)")
      ->check(CLI::Range(1, 3));
  cmd->add_flag("--no-noise", cli->no_noise, "ideal sensor: no noise, blur or exposure changes");
  cmd->add_option("--textures", cli->textures,
                  std::string("directory of the photographs used as textures (default ") +
                      synth::kDefaultTextureDir + ", procedural stand-ins if absent)");
  cmd->add_option(
      "--trajectory", cli->options.trajectory_file,
      "drive the camera along this TUM trajectory (re-expressed in the room; real frame timestamps "
      "from an associations.txt next to it)");
  cmd->add_option("--threads", cli->options.threads, "worker threads (default: all cores)");
  cmd->add_option("--supersample", cli->options.supersample,
                  "anti-aliasing supersampling factor 1..4")
      ->capture_default_str();
  cmd->add_flag("--force", cli->options.force, "overwrite a non-empty output directory");
  cmd->callback([cli] { RunSynth(*cli); });
});

}  // namespace
}  // namespace dynorb
