#include "dynorb/eval/trajectory_generator.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>

#include "dynorb/core/angles.h"
#include "dynorb/core/error.h"

namespace dynorb {
namespace {

constexpr double kStartStamp_s = 1.3e9;

// Platform-independent random numbers (std::*_distribution is implementation-defined).
class Random {
 public:
  explicit Random(uint64_t seed) : engine_(seed) {}
  double Uniform() {
    return (static_cast<double>(engine_() >> 11) + 0.5) * (1.0 / 9007199254740992.0);
  }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  double Gaussian() {
    const double u1 = Uniform(), u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }
  Eigen::Vector3d Gaussian3() { return {Gaussian(), Gaussian(), Gaussian()}; }
  Eigen::Vector3d UnitVector() {
    Eigen::Vector3d v = Gaussian3();
    return v.norm() > 1e-9 ? v.normalized() : Eigen::Vector3d::UnitX();
  }

 private:
  std::mt19937_64 engine_;
};

// A 1-D smooth signal: sum of three slow sinusoids.
struct Wave {
  double amplitude[3], frequency_hz[3], phase[3];
  double At(double t) const {
    double v = 0.0;
    for (int k = 0; k < 3; ++k)
      v += amplitude[k] * std::sin(2.0 * kPi * frequency_hz[k] * t + phase[k]);
    return v;
  }
};

Wave MakeWave(Random& rng, double amplitude) {
  Wave w{};
  for (int k = 0; k < 3; ++k) {
    w.amplitude[k] = amplitude / (k + 1.0) * rng.Uniform(0.6, 1.0);
    w.frequency_hz[k] = rng.Uniform(0.03, 0.12) * (k + 1.0);
    w.phase[k] = rng.Uniform(0.0, 2.0 * kPi);
  }
  return w;
}

Eigen::Quaterniond SmallRotation(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle < 1e-15) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, rotation_vector / angle));
}

Trajectory SmoothPath(Random& rng, double duration_s, double rate_hz) {
  const Wave x = MakeWave(rng, 0.8), y = MakeWave(rng, 0.6), z = MakeWave(rng, 0.15);
  const Wave yaw = MakeWave(rng, 0.6), pitch = MakeWave(rng, 0.15), roll = MakeWave(rng, 0.08);
  const Eigen::Vector3d origin(rng.Uniform(-1, 1), rng.Uniform(-1, 1), 1.4);
  // Camera frame: z forward, y down. Base orientation looks horizontally along world +x.
  Eigen::Matrix3d world_from_base;
  world_from_base << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Eigen::Quaterniond base(world_from_base);
  const int n = static_cast<int>(std::floor(duration_s * rate_hz)) + 1;
  Trajectory path(n);
  for (int k = 0; k < n; ++k) {
    const double t = k / rate_hz;
    path[k].timestamp_s = kStartStamp_s + t;
    const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw.At(t), Eigen::Vector3d::UnitZ()) * base *
                                 Eigen::AngleAxisd(pitch.At(t), Eigen::Vector3d::UnitX()) *
                                 Eigen::AngleAxisd(roll.At(t), Eigen::Vector3d::UnitZ());
    path[k].world_from_cam = Rigid3d(q, origin + Eigen::Vector3d(x.At(t), y.At(t), z.At(t)));
  }
  return path;
}

}  // namespace

void TrajectoryPairOptions::Validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v)) throw InputError(std::string(name) + " must be positive");
  };
  auto non_negative = [](double v, const char* name) {
    if (!(v >= 0.0) || !std::isfinite(v)) throw InputError(std::string(name) + " must be >= 0");
  };
  positive(duration_s, "--duration-s");
  positive(rate_hz, "--rate-hz");
  positive(scale, "--scale");
  non_negative(noise_m, "--noise-m");
  non_negative(drift_m_per_s, "--drift-m-per-s");
  non_negative(stamp_jitter_s, "stamp jitter");
  if (!(drop_fraction >= 0.0 && drop_fraction < 1.0))
    throw InputError("drop fraction must be in [0, 1)");
  // Bounds that keep the files readable (the TUM reader takes positions up to 1e9 m) and the
  // estimate long enough to evaluate.
  auto at_most = [](double v, double limit, const char* name) {
    if (v > limit) {
      std::ostringstream text;
      text << name << " must be <= " << limit << ", got " << v;
      throw InputError(text.str());
    }
  };
  at_most(scale, 1e3, "--scale");
  at_most(noise_m, 1e3, "--noise-m");
  at_most(drift_m_per_s, 1e3, "--drift-m-per-s");
  if (duration_s * rate_hz * (1.0 - drop_fraction) < 2.0)
    throw InputError(
        "the estimate would keep fewer than 2 poses (--duration-s x --rate-hz x (1 - "
        "--drop-fraction))");
  if (duration_s * rate_hz > 5e7)
    throw InputError("--duration-s x --rate-hz is too large (> 5e7 poses)");
}

Trajectory GenerateSmoothTrajectory(uint64_t seed, double duration_s, double rate_hz) {
  Random rng(seed);
  return SmoothPath(rng, duration_s, rate_hz);
}

TrajectoryPair GenerateTrajectoryPair(const TrajectoryPairOptions& options) {
  options.Validate();
  Random rng(options.seed);
  TrajectoryPair pair;
  pair.groundtruth = SmoothPath(rng, options.duration_s, options.rate_hz);
  pair.est_world_from_gt_world =
      Rigid3d(SmallRotation(rng.UnitVector() * rng.Uniform(0.5, 2.5)),
              Eigen::Vector3d(rng.Uniform(-2, 2), rng.Uniform(-2, 2), rng.Uniform(-1, 1)));
  const Eigen::Vector3d drift_direction = rng.UnitVector();
  const double t0 = pair.groundtruth.front().timestamp_s;
  // At most a quarter frame, so that estimate stamps stay strictly increasing.
  const double max_jitter_s = std::min(options.stamp_jitter_s, 0.25 / options.rate_hz);
  for (const StampedPose& gt : pair.groundtruth) {
    // Draw every random number for every frame so that the sequence does not depend on drops.
    const bool drop = rng.Uniform() < options.drop_fraction;
    const double jitter = rng.Uniform(-max_jitter_s, max_jitter_s);
    const Eigen::Vector3d position_noise = options.noise_m * rng.Gaussian3();
    const Eigen::Vector3d rotation_noise = options.noise_m * rng.Gaussian3();
    if (drop) continue;
    const double elapsed_s = gt.timestamp_s - t0;
    Rigid3d perturbed = gt.world_from_cam;
    perturbed.translation += options.drift_m_per_s * elapsed_s * drift_direction + position_noise;
    perturbed.translation *= options.scale;
    perturbed.rotation = (perturbed.rotation * SmallRotation(rotation_noise)).normalized();
    StampedPose est;
    est.timestamp_s = gt.timestamp_s + jitter;
    est.world_from_cam = pair.est_world_from_gt_world * perturbed;
    pair.estimate.push_back(est);
  }
  return pair;
}

}  // namespace dynorb
