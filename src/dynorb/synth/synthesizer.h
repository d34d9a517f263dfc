// Synthesizer: generates a synthetic dynamic RGB-D sequence (see docs/synthetic.md): the office
// scene, a camera path (preset or real TUM trajectory), moving people and objects, rendering,
// sensor effects, and the TUM-layout output.
//
// Every frame is a pure function of (options, frame index): frames are rendered in parallel and
// the output is bit-identical for a given seed and version whatever the thread count. With
// `static_twin`, the same sequence without any moving object (same noise seeds), for
// ATE(dynamic) / ATE(static twin). SequenceSynth is immutable after construction and
// thread-safe; each thread needs its own Renderer.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/synth/camera_motion.h"
#include "dynorb/synth/movers.h"
#include "dynorb/synth/office.h"
#include "dynorb/synth/renderer.h"
#include "dynorb/synth/sensor_noise.h"

namespace dynorb::synth {

inline constexpr const char* kDefaultTextureDir = "/usr/share/doc/opencv-doc/examples/data";
// 2: people at rest keep their orientation; 3: parallax-correct sprites; 4: camera.yaml ThDepth 50.
inline constexpr const char* kSynthVersion = "4";

struct SynthOptions {
  std::string preset = "walking_xyz";  // one of Presets() (camera motion, duration, people mode)
  uint64_t seed = 1;                   // drives layout details, paths, noise
  std::string out_dir;                 // output directory (Synthesize only)
  static constexpr int kMaxFrames = 1000000;  // --frames above this is refused (memory)
  int frames = 0;            // number of frames; 0 = the preset's (or trajectory's) duration
  bool static_twin = false;  // remove every moving object
  std::string people_dir;    // RGBA *.png cut-outs of real people; empty = procedural figures
  int num_people = 0;        // 1..3; 0 = 2
  std::string texture_dir = kDefaultTextureDir;  // photographs (opencv-doc examples/data)
  bool texture_dir_explicit = false;  // missing explicit dir/file = error; default = warning
  std::string trajectory_file;        // TUM trajectory driving the camera instead of the preset
  bool noise = true;                  // sensor noise, blur, exposure changes (off: ideal sensor)
  bool force = false;                 // overwrite a non-empty output directory
  int threads = 0;                    // worker threads; 0 = hardware concurrency
  int supersample = 2;                // anti-aliasing factor (1..4)
  std::string command_line;           // recorded in scene.yaml

  void Validate() const;  // throws InputError
};

struct SynthFrame {
  int index = 0;
  FrameTime time;
  Rigid3d world_from_cam;
  cv::Mat rgb;        // CV_8UC3 BGR, with sensor effects
  cv::Mat depth_u16;  // CV_16U, factor 5000
  cv::Mat depth_m;    // CV_32F ideal depth (0 = none)
  cv::Mat mask;       // CV_8U object ids
  std::vector<ObjectState> objects;
};

class SequenceSynth {
 public:
  explicit SequenceSynth(const SynthOptions& options);  // throws InputError on bad input

  int num_frames() const { return static_cast<int>(times_.size()); }
  std::unique_ptr<Renderer> MakeRenderer() const;
  SynthFrame RenderFrame(int index, Renderer* renderer) const;
  const PinholeCamera& camera() const { return camera_; }
  const std::vector<FrameTime>& times() const { return times_; }
  Rigid3d WorldFromCam(double t_s) const { return path_->WorldFromCam(t_s); }
  const std::vector<std::string>& warnings() const { return warnings_; }
  std::string SceneYaml() const;  // every generation parameter

 private:
  SynthOptions options_;
  Preset preset_;
  PinholeCamera camera_;
  std::unique_ptr<Office> office_;
  std::unique_ptr<CameraPath> path_;
  std::unique_ptr<Movers> movers_;
  std::vector<FrameTime> times_;
  std::vector<std::string> warnings_, sprite_names_;
  std::string timestamps_source_;
  SensorOptions sensor_;
  SmoothNoise exposure_;
  std::vector<std::unique_ptr<Texture>> sprite_textures_;
};

using ProgressFn = std::function<void(int done, int total)>;

struct SynthReport {
  int frames = 0;
  double seconds = 0.0;
  std::vector<std::string> warnings;
};

// Generates the sequence into options.out_dir (progress is called from the calling thread).
SynthReport Synthesize(const SynthOptions& options, const ProgressFn& progress = {});

}  // namespace dynorb::synth
