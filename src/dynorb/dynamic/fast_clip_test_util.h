// Helpers of the FAST filter's end-to-end tests: a clip of a synthetic preset rendered in memory
// (with its ground truth), the filter's input for one of its frames, and a keypoint's pixel.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/dynamic/keypoint_filter.h"
#include "dynorb/dynamic/pixel.h"
#include "dynorb/synth/synthesizer.h"

namespace dynorb {

struct ClipFrame {
  cv::Mat bgr, gray, depth_m;  // as a run sees them (sensor noise, depth in metres)
  cv::Mat ideal_depth_m;       // noiseless depth (0 = none)
  cv::Mat mask;                // object ids
  cv::Mat still;               // mask pixels of objects standing still in this frame
  Rigid3d world_from_cam;
  std::vector<synth::ObjectState> objects;
};

struct Clip {
  PinholeCamera camera;
  std::vector<ClipFrame> frames;
};

// Frames [first, first + count) of `preset` with data seed `seed` (procedural people, no
// supersampling); `sequence_frames` > 0 shortens the sequence (its trajectory and movers follow).
inline Clip RenderClip(const std::string& preset, uint64_t seed, int sequence_frames, int first,
                       int count) {
  synth::SynthOptions o;
  o.preset = preset;
  o.seed = seed;
  o.frames = sequence_frames;
  o.supersample = 1;
  o.threads = 1;
  synth::SequenceSynth synth(o);
  Clip clip;
  clip.camera = synth.camera();
  auto renderer = synth.MakeRenderer();
  for (int i = first; i < first + count; ++i) {
    const synth::SynthFrame f = synth.RenderFrame(i, renderer.get());
    ClipFrame frame;
    frame.bgr = f.rgb;
    cv::cvtColor(f.rgb, frame.gray, cv::COLOR_BGR2GRAY);
    f.depth_u16.convertTo(frame.depth_m, CV_32F, 1.0 / 5000.0);
    frame.ideal_depth_m = f.depth_m;
    frame.mask = f.mask;
    frame.still = cv::Mat::zeros(f.mask.size(), CV_8U);
    for (const synth::ObjectState& object : f.objects) {
      if (!object.moving) frame.still.setTo(255, f.mask == object.id);
    }
    frame.world_from_cam = f.world_from_cam;
    frame.objects = f.objects;
    clip.frames.push_back(frame);
  }
  return clip;
}

// The filter's input for frame `index` of a clip (no motion prediction).
inline FilterInput ClipInput(const ClipFrame& f, const KeypointSet& set, size_t index) {
  FilterInput input;
  input.frame_id = index;
  input.bgr = &f.bgr;
  input.gray = &f.gray;
  input.depth_m = &f.depth_m;
  input.keypoints = &set;
  return input;
}

// The pixel of a keypoint (rounded, clamped to the image).
inline cv::Point KeypointPixel(const cv::KeyPoint& kp, const cv::Size& size) {
  return NearestPixel(kp.pt, size);
}

}  // namespace dynorb
