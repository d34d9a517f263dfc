// Shared set-up of the optimisers that solve one Ceres problem in stages: robust (Huber with the
// χ² gates of 2-D and 3-D observations), then plain L2, removing outliers in between instead of
// rebuilding the problem (building it costs as much as an LM iteration).
// Internal to optimization/. Not thread-safe; one per solve.
#pragma once

#include <cmath>

#include <ceres/loss_function.h>
#include <ceres/problem.h>

namespace dynorb {

class StagedLosses {
 public:
  StagedLosses(double chi2_mono, double chi2_stereo)
      : mono_(new ceres::HuberLoss(std::sqrt(chi2_mono)), ceres::TAKE_OWNERSHIP),
        stereo_(new ceres::HuberLoss(std::sqrt(chi2_stereo)), ceres::TAKE_OWNERSHIP) {}
  // The loss of an observation (shared by all blocks; the problem must not own it).
  ceres::LossFunction* For(bool stereo) { return stereo ? &stereo_ : &mono_; }
  // From now on the Huber widths are sqrt of these gates.
  void Rescale(double chi2_mono, double chi2_stereo) {
    mono_.Reset(new ceres::HuberLoss(std::sqrt(chi2_mono)), ceres::TAKE_OWNERSHIP);
    stereo_.Reset(new ceres::HuberLoss(std::sqrt(chi2_stereo)), ceres::TAKE_OWNERSHIP);
  }
  // From now on every block using these losses is plain L2.
  void SwitchToL2() {
    mono_.Reset(nullptr, ceres::TAKE_OWNERSHIP);
    stereo_.Reset(nullptr, ceres::TAKE_OWNERSHIP);
  }

 private:
  ceres::LossFunctionWrapper mono_, stereo_;
};

// Problem options for StagedLosses: manifolds owned, losses not, O(1) residual removal.
inline ceres::Problem::Options StagedProblemOptions() {
  ceres::Problem::Options options;
  options.manifold_ownership = ceres::TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.enable_fast_removal = true;
  return options;
}

}  // namespace dynorb
