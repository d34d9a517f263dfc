#include "dynorb/synth/camera_motion.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "dynorb/core/angles.h"
#include "dynorb/core/error.h"
#include "dynorb/io/text_lines.h"

namespace dynorb::synth {
namespace {

}  // namespace

const std::vector<Preset>& Presets() {
  static const std::vector<Preset> presets = {
      {"walking_xyz", 28.8, CameraMotion::kXyz, false},
      {"walking_static", 24.8, CameraMotion::kStatic, false},
      {"walking_rpy", 30.6, CameraMotion::kRpy, false},
      {"walking_halfsphere", 35.8, CameraMotion::kHalfsphere, false},
      {"sitting_static", 23.6, CameraMotion::kStatic, true},
      {"sitting_xyz", 42.5, CameraMotion::kXyz, true},
      {"sitting_rpy", 27.5, CameraMotion::kRpy, true},
      {"sitting_halfsphere", 37.2, CameraMotion::kHalfsphere, true},
  };
  return presets;
}

const Preset* FindPreset(const std::string& name) {
  for (const Preset& p : Presets())
    if (p.name == name) return &p;
  return nullptr;
}

std::string PresetNames() {
  std::string names;
  for (const Preset& p : Presets()) names += (names.empty() ? "" : ", ") + p.name;
  return names;
}

Rigid3d LookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target) {
  const Eigen::Vector3d forward = (target - position).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d r;
  r.col(0) = right;
  r.col(1) = down;
  r.col(2) = forward;
  return Rigid3d(r, position);
}

SmoothNoise::SmoothNoise(uint64_t seed, double min_hz, double max_hz, int terms) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double power = 0.0;
  for (int i = 0; i < terms; ++i) {
    const double f = min_hz * std::pow(max_hz / min_hz, unit(rng));
    freq_.push_back(f);
    phase_.push_back(2.0 * kPi * unit(rng));
    amp_.push_back(1.0 / f);
    power += 0.5 / (f * f);
  }
  for (double& a : amp_) a /= std::sqrt(power);
}

double SmoothNoise::operator()(double t) const {
  double v = 0.0;
  for (size_t i = 0; i < freq_.size(); ++i)
    v += amp_[i] * std::sin(2.0 * kPi * freq_[i] * t + phase_[i]);
  return v;
}

CameraPath::CameraPath(const Preset& preset, const Eigen::Vector3d& anchor,
                       const Eigen::Vector3d& target, uint64_t seed)
    : preset_(preset), anchor_(anchor), target_(target), duration_s_(preset.duration_s) {
  // 0-2: slow wander of position, 3-5: hand tremor of position, 6-8: tremor of orientation.
  for (int i = 0; i < 9; ++i) {
    const uint64_t s = seed * 0x9E3779B97F4A7C15ULL + 1000 + i;
    noise_.emplace_back(s, i < 3 ? 0.05 : 0.6, i < 3 ? 0.3 : 4.0);
  }
}

CameraPath::CameraPath(const Trajectory& trajectory, const Rigid3d& start)
    : trajectory_(trajectory) {
  if (trajectory_.size() < 2) throw InputError("trajectory needs at least two poses");
  start_from_first_ = start * trajectory_.front().world_from_cam.Inverse();
  duration_s_ = trajectory_.back().timestamp_s - trajectory_.front().timestamp_s;
}

Rigid3d CameraPath::Interpolate(double timestamp_s) const {
  auto it = std::lower_bound(trajectory_.begin(), trajectory_.end(), timestamp_s,
                             [](const StampedPose& p, double ts) { return p.timestamp_s < ts; });
  if (it == trajectory_.begin()) return it->world_from_cam;
  if (it == trajectory_.end()) return trajectory_.back().world_from_cam;
  const StampedPose& b = *it;
  const StampedPose& a = *(it - 1);
  const double f = (timestamp_s - a.timestamp_s) / (b.timestamp_s - a.timestamp_s);
  return Rigid3d(a.world_from_cam.rotation.slerp(f, b.world_from_cam.rotation),
                 (1.0 - f) * a.world_from_cam.translation + f * b.world_from_cam.translation);
}

Rigid3d CameraPath::WorldFromCam(double t) const {
  if (!trajectory_.empty())
    return start_from_first_ * Interpolate(trajectory_.front().timestamp_s + t);
  const auto& n = noise_;
  const double w = 2.0 * kPi;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // world x right, y forward, z up
  Eigen::Vector3d target = target_;
  double yaw = 0.0, pitch = 0.0, roll = 0.0;
  switch (preset_.motion) {
    case CameraMotion::kXyz: {
      const double amp = preset_.sitting ? 0.7 : 1.0;
      offset =
          amp * Eigen::Vector3d(0.32 * std::sin(w * t / 9.0), 0.25 * std::sin(w * t / 12.5 + 1.0),
                                0.18 * std::sin(w * t / 7.0 + 2.0));
      offset += 0.04 * Eigen::Vector3d(n[0](t), n[1](t), n[2](t));
      target += 0.15 * Eigen::Vector3d(n[1](t + 40.0), 0.0, n[2](t + 40.0));
      break;
    }
    case CameraMotion::kStatic:
      offset = 0.008 * Eigen::Vector3d(n[0](t), n[1](t), n[2](t));
      break;
    case CameraMotion::kRpy: {
      offset = 0.05 * Eigen::Vector3d(n[0](t), n[1](t), n[2](t));
      const double amp = preset_.sitting ? 0.8 : 1.0;
      yaw = amp * DegToRad(20.0) * std::sin(w * t / 8.0);
      pitch = amp * DegToRad(12.0) * std::sin(w * t / 6.0 + 1.0);
      roll = amp * DegToRad(16.0) * std::sin(w * t / 5.0 + 2.0);
      break;
    }
    case CameraMotion::kHalfsphere: {
      // On a sphere of ~1 m diameter around a point 0.5 m in front of the anchor.
      const double azimuth = DegToRad(70.0) * std::sin(w * t / 14.0);
      const double elevation = DegToRad(35.0) * std::sin(w * t / 9.0 + 0.5);
      const Eigen::Vector3d dir(std::sin(azimuth) * std::cos(elevation),
                                -std::cos(azimuth) * std::cos(elevation), std::sin(elevation));
      offset = Eigen::Vector3d(0.0, 0.5, 0.0) + 0.5 * dir +
               0.02 * Eigen::Vector3d(n[0](t), n[1](t), n[2](t));
      break;
    }
  }
  // Hand tremor: millimetres and a few tenths of a degree.
  const double tremor = preset_.motion == CameraMotion::kStatic ? 0.0015 : 0.003;
  offset += tremor * Eigen::Vector3d(n[3](t), n[4](t), n[5](t));
  yaw += DegToRad(0.3) * n[6](t);
  pitch += DegToRad(0.3) * n[7](t);
  roll += DegToRad(0.2) * n[8](t);
  const Rigid3d look = LookAt(anchor_ + offset, target);
  // Orientation offsets in the camera frame: yaw about y (down), pitch about x, roll about z.
  const Eigen::Quaterniond turn = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ());
  return Rigid3d(look.rotation * turn, look.translation);
}

std::vector<FrameTime> MakeFrameTimes(int frames, double start_timestamp_s, uint64_t seed) {
  std::mt19937_64 rng(seed * 0xD1B54A32D192ED03ULL + 77);
  std::uniform_real_distribution<double> jitter(-0.001, 0.001), depth_delay(0.0005, 0.004);
  std::vector<FrameTime> times;
  for (int k = 0; k < frames; ++k) {
    FrameTime f;
    f.t_s = k / 30.0 + (k > 0 ? jitter(rng) : 0.0);
    f.rgb_ts = start_timestamp_s + f.t_s;
    f.depth_ts = f.rgb_ts + depth_delay(rng);
    times.push_back(f);
  }
  return times;
}

std::vector<FrameTime> ReadFrameTimes(const std::string& associations_path, double first_ts,
                                      double duration_s) {
  std::vector<FrameTime> times;
  ForEachDataLine(associations_path, [&](int line, const std::vector<std::string>& fields) {
    if (fields.size() < 3)
      throw InputErrorAt(associations_path, line, "expected 'rgb_ts rgb_file depth_ts ...'");
    const double rgb = ParseDouble(fields[0], associations_path, line);
    const double depth = ParseDouble(fields[2], associations_path, line);
    if (rgb < first_ts || rgb > first_ts + duration_s) return;
    // Compared as written (microseconds, SequenceWriter::Stamp): two frames may not share a file.
    auto micros = [](double t) { return std::llround(t * 1e6); };
    if (!times.empty() && micros(rgb) <= micros(times.back().rgb_ts))
      throw InputErrorAt(associations_path, line, "rgb timestamps must increase (by >= 1 us)");
    if (!times.empty() && micros(depth) <= micros(times.back().depth_ts))
      throw InputErrorAt(associations_path, line, "depth timestamps must increase (by >= 1 us)");
    times.push_back({rgb - first_ts, rgb, depth});
  });
  if (times.empty())
    throw InputError(associations_path + ": no frame within the trajectory's time span");
  return times;
}

}  // namespace dynorb::synth
