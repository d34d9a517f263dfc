// Camera motion of a synthetic sequence: hand-held paths mirroring the TUM fr3 dynamic sequences
// (presets), or a real TUM trajectory re-expressed in the synthetic room; plus frame timestamps.
//
// Poses are world_from_cam (TUM convention) as functions of the time since the first frame.
// Hand-held jitter is a smooth deterministic function of time (sums of sinusoids with seeded
// frequencies and phases), so any frame can be computed on its own. Immutable; thread-safe.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "dynorb/core/rigid3.h"
#include "dynorb/core/trajectory.h"

namespace dynorb::synth {

enum class CameraMotion { kXyz, kStatic, kRpy, kHalfsphere };

struct Preset {
  std::string name;
  double duration_s;  // as the TUM sequence it mirrors
  CameraMotion motion;
  bool sitting;  // people stay at the desks and move little
};

const std::vector<Preset>& Presets();
// nullptr if unknown.
const Preset* FindPreset(const std::string& name);
std::string PresetNames();  // "a, b, c"

// A camera looking from `position` at `target`, upright (world z up).
Rigid3d LookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target);

// Smooth, zero-mean, unit-RMS noise in time: a sum of sinusoids with frequencies in
// [min_hz, max_hz] (amplitude ~ 1/f) and seeded phases.
class SmoothNoise {
 public:
  SmoothNoise(uint64_t seed, double min_hz, double max_hz, int terms = 6);
  double operator()(double t) const;

 private:
  std::vector<double> freq_, phase_, amp_;
};

class CameraPath {
 public:
  // A preset motion around `anchor`, filming `target`.
  CameraPath(const Preset& preset, const Eigen::Vector3d& anchor, const Eigen::Vector3d& target,
             uint64_t seed);
  // A real trajectory (world_from_cam samples), re-expressed so that its first pose is `start`:
  // world_from_cam(t) = start * gt(t0)^-1 * gt(t0 + t), interpolated (slerp + linear).
  CameraPath(const Trajectory& trajectory, const Rigid3d& start);

  Rigid3d WorldFromCam(double t_s) const;
  double duration_s() const { return duration_s_; }
  // For trajectory paths: timestamp of the trajectory's first pose (else 0).
  double first_timestamp_s() const {
    return trajectory_.empty() ? 0.0 : trajectory_.front().timestamp_s;
  }

 private:
  Rigid3d Interpolate(double timestamp_s) const;

  Preset preset_{};
  Eigen::Vector3d anchor_, target_;
  std::vector<SmoothNoise> noise_;
  Trajectory trajectory_;
  Rigid3d start_from_first_;
  double duration_s_ = 0.0;
};

struct FrameTime {
  double t_s;     // since the first frame (drives the scene)
  double rgb_ts;  // TUM timestamps (seconds)
  double depth_ts;
};

// 30 Hz frames with TUM-like timestamp jitter (rgb +-1 ms) and depth stamps 0.5-4 ms later.
std::vector<FrameTime> MakeFrameTimes(int frames, double start_timestamp_s, uint64_t seed);
// Frames at the real timestamps of a TUM associations file (rgb_ts rgb/.. depth_ts depth/..)
// that fall within [first_ts, first_ts + duration_s]. Throws InputError on malformed lines.
std::vector<FrameTime> ReadFrameTimes(const std::string& associations_path, double first_ts,
                                      double duration_s);

}  // namespace dynorb::synth
