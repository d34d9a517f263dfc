// Smoothed constant-velocity model of the camera centre, the source of the tracker's motion prior
// (tracking.motion_prior_sigma_m / motion_prior_velocity_gain; docs/slam_core.md).
//
// The velocity (world frame, m/s) is an exponential average of the tracked centres' motion,
// started as a plain mean (the gain of the n-th update after a reset is max(gain, 1/n)), and the
// prior is given only once kMinUpdates frame-to-frame motions have been averaged: one difference
// of two noisy centres (say the relocalised pose and the next) is no velocity to pull toward. The
// prediction for a frame dt after the last tracked one is that frame's centre + dt x velocity,
// with standard deviation sigma; after dropped frames (an interval over 1.5 times the last one;
// timestamp jitter stays below) sigma grows with the square of the ratio, since the acceleration
// the model ignores moves the camera that much more. Frame-agnostic: the tracker passes centres
// in the map's current frame. Not thread-safe; deterministic.
#pragma once

#include <optional>

#include <Eigen/Core>

#include "dynorb/optimization/pose_optimizer.h"

namespace dynorb {

class CentreMotionModel {
 public:
  // sigma_m <= 0: disabled (Predict never gives a prior).
  CentreMotionModel(double sigma_m, double velocity_gain)
      : sigma_m_(sigma_m), gain_(velocity_gain) {}

  bool enabled() const { return sigma_m_ > 0.0; }

  static constexpr int kMinUpdates = 3;

  // The prior for a frame dt seconds after the last tracked one, whose centre is `last_centre`;
  // none while disabled, before kMinUpdates updates since the start or the last Reset, or for
  // dt <= 0.
  std::optional<CentrePrior> Predict(const Eigen::Vector3d& last_centre, double dt) const;

  // A frame tracked dt seconds (> 0) after the last one: their centres update the velocity.
  void Update(const Eigen::Vector3d& centre, const Eigen::Vector3d& last_centre, double dt);

  // Forget the velocity (after relocalisation or a lost frame: the last frame may be anywhere).
  void Reset();

 private:
  double sigma_m_;
  double gain_;
  std::optional<Eigen::Vector3d> velocity_;
  int updates_ = 0;          // Since the start or the last Reset.
  double interval_s_ = 0.0;  // Interval of the last update (0: none).
};

}  // namespace dynorb
