// `dynorb run`: RGB-D SLAM on a TUM-format sequence folder (thin CLI over run_pipeline.h).
#include <iostream>
#include <memory>

#include <CLI/CLI.hpp>

#include "command_registry.h"
#include "run_modes.h"
#include "run_pipeline.h"
#include "run_report.h"

namespace dynorb {
namespace {

const bool kRegistered = RegisterCommand("run", 10, [](CLI::App& app) {
  auto cli = std::make_shared<RunRequest>();
  CLI::App* cmd = app.add_subcommand("run", "Run RGB-D SLAM on a TUM-format sequence folder (TUM, Bonn or dynorb synth)");
  cmd->add_option("--dataset", cli->dataset, "Sequence folder (rgb.txt, depth.txt, optional groundtruth.txt)")->required();
  cmd->add_option("--config", cli->config, "Camera/system YAML (ORB-SLAM2 keys accepted); default: DATASET/camera.yaml");
  cmd->add_option("--config-overlay", cli->config_overlays,
                  "YAML applied over the config, e.g. a mode section ('fast:' with "
                  "'correspondences: descriptors'); "
                  "repeatable, later files win; effective_config.yaml shows the result");
  cmd->add_option("--out", cli->out, "Output folder (created if needed)")->required();
  cmd->add_option("--mode", cli->mode, "Dynamic-object handling: " + RunModeHelp())
      ->check(CLI::IsMember(RunModeNames()));
  cmd->add_option("--models", cli->models, "Detector model folder (semantic/fused; default $DYNORB_MODELS, else ../shared/models or the checkout's ../shared/models when present, else models/)");
  cmd->add_option("--save-overlays", cli->overlays,
                  "Write one image per frame: kept keypoints green, removed (dynamic) ones red, plus the mode's evidence");
  cmd->add_option("--overlay-every", cli->overlay_every,
                  "With --save-overlays: only every N-th frame (drawing is timed as part of the filter)")
      ->check(IntAtLeast(1));
  cmd->add_option("--run-mode", cli->run_mode, "sequential (deterministic) or parallel (mapping thread)")
      ->check(CLI::IsMember({"sequential", "parallel"}));
  cmd->add_flag("--pipeline,!--no-pipeline", cli->pipeline,
               "Run the next frames' detection/filter/description on a second thread while this frame is tracked "
               "(default; deterministic; the filter's motion prediction is --pipeline-depth frames older). "
               "--no-pipeline: one frame at a time");
  cmd->add_option("--pipeline-depth", cli->pipeline_depth,
                  "With --pipeline: how many frames' front ends may run ahead of tracking (1..16, default 4; more lets the "
                  "worker keep going while a keyframe is mapped; deterministic; the motion prediction is that many frames "
                  "older; live, each frame ahead adds a frame period of latency)")
      ->check(CLI::Range(1, kMaxPipelineDepth));
  cmd->add_option("--front-end-threads", cli->front_end_threads,
                  "With --pipeline: 1 runs the front ends on one thread; 2 detects the next frame's ORB keypoints "
                  "on one thread while the filter and description of the frame before run on another (same "
                  "results); 0 (default): 2 in the modes that filter keypoints, 1 in plain mode")
      ->check(CLI::Range(0, 2));
  cmd->add_flag("--preload", cli->preload,
                "Decode every frame into memory before the run starts, so that the timing is that of a live camera "
                "(no PNG decoding competing for the cores); about 2.2 MB per 640x480 frame (2.8 MB with ground-truth masks), refused when more than "
                "half the machine's memory");
  cmd->add_option("--seed", cli->seed, "Seed of the randomised steps (RANSAC)")->check(NonNegativeInteger());
  cmd->add_option("--frames", cli->frames, "Frame range A:B (0-based, B exclusive; either side may be empty)");
  cmd->add_flag(
      "--save-map", cli->save_map,
      "Also write OUT/map.ply: the final map's landmarks as a coloured point cloud (binary PLY; "
      "MeshLab, CloudCompare, Open3D), with each point's dynamic_object_id (the masks' object id; "
      "0: none) when the sequence has ground-truth masks");
  cmd->add_flag("--quiet", cli->quiet, "No progress bar");
  cmd->callback([cli] {
    const nlohmann::json stats = RunPipeline(*cli);
    std::cout << FormatRunSummary(stats) << "outputs: " << cli->out
              << "/{trajectory.txt,keyframes.txt,stats.json,frames.csv,effective_config.yaml"
              << (cli->save_map ? ",map.ply" : "") << "}\n";
  });
});

}  // namespace
}  // namespace dynorb
