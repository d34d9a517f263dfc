#include "dynorb/tracking/centre_motion_model.h"

#include <algorithm>

namespace dynorb {

std::optional<CentrePrior> CentreMotionModel::Predict(const Eigen::Vector3d& last_centre,
                                                      double dt) const {
  if (!enabled() || !velocity_ || updates_ < kMinUpdates || !(dt > 0.0)) return std::nullopt;
  CentrePrior prior;
  prior.centre_in_world = last_centre + dt * *velocity_;
  const double stretch = interval_s_ > 0.0 && dt > 1.5 * interval_s_ ? dt / interval_s_ : 1.0;
  prior.sigma_m = sigma_m_ * stretch * stretch;
  return prior;
}

void CentreMotionModel::Update(const Eigen::Vector3d& centre, const Eigen::Vector3d& last_centre,
                               double dt) {
  interval_s_ = dt;
  const Eigen::Vector3d velocity = (centre - last_centre) / dt;
  ++updates_;
  if (!velocity_) {
    velocity_ = velocity;
  } else {
    *velocity_ += std::max(gain_, 1.0 / updates_) * (velocity - *velocity_);
  }
}

void CentreMotionModel::Reset() {
  velocity_.reset();
  updates_ = 0;
  interval_s_ = 0.0;
}

}  // namespace dynorb
