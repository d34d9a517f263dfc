// The `dynorb run` pipeline as a function, shared by `dynorb run` and `dynorb bench`: reads a
// TUM-format folder, runs SLAM with the chosen mode, writes trajectory.txt, keyframes.txt,
// effective_config.yaml and stats.json into `out`, and returns the stats.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dynorb/io/bench_suite.h"  // kMaxPipelineDepth

namespace dynorb {

struct RunRequest {
  std::string dataset;                 // sequence folder
  std::string config;                  // YAML; empty: DATASET/camera.yaml
  std::vector<std::string>
      config_overlays;                 // YAML files applied over it, in order (their keys win)
  std::string out;                     // output folder (created)
  std::string mode = "plain";          // see run_modes.h
  std::string run_mode = "sequential"; // or "parallel"
  uint64_t seed = 0;
  std::string frames;                  // "A:B" or empty
  std::string models;                  // detector model folder (semantic modes)
  std::string overlays;                // folder for overlay images; empty: none
  int overlay_every = 1;               // draw and save the overlay of every k-th frame only
  bool pipeline = true;                // next frames' front ends overlap this frame's tracking
  int pipeline_depth = 4;              // frames whose front end may run ahead (with pipeline)
  int front_end_threads = 0;           // with pipeline: SystemOptions::front_end_threads (0: auto)
  bool quiet = false;                  // no progress bar
  // Decode every frame before the run (timing as with a live camera: no PNG decoding competing
  // for the cores; memory ~2.2-2.8 MB per 640x480 frame, checked against the machine's).
  bool preload = false;
  // Also write OUT/map.ply: the final map's landmarks, coloured from their keyframe's image.
  bool save_map = false;
};

// Throws InputError for bad input (nothing is written then, or only complete files).
nlohmann::json RunPipeline(const RunRequest& request);

// Reads `files` (YAML, in order) with the schema of a run in `mode` and throws InputError for an
// unknown key or a bad value: what RunPipeline would refuse, found before any run (`dynorb bench`).
void CheckRunConfigFiles(const std::string& mode, const std::vector<std::string>& files);

}  // namespace dynorb
