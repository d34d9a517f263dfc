#include "dynorb/eval/association.h"

#include <cmath>
#include <string>

#include "dynorb/core/error.h"
#include "dynorb/core/stamp_association.h"
#include "dynorb/eval/text_format.h"

namespace dynorb {
namespace {

void CheckIncreasing(const std::vector<double>& stamps, const char* what) {
  for (size_t i = 1; i < stamps.size(); ++i) {
    if (!(stamps[i] > stamps[i - 1])) {
      throw InputError(std::string(what) + " timestamps must be strictly increasing (index " +
                       std::to_string(i) + ")");
    }
  }
}

}  // namespace

void StampAssociationOptions::Validate() const {
  if (!(max_diff_s > 0.0) || !std::isfinite(max_diff_s)) {
    throw InputError("--max-diff must be a positive number of seconds, got " +
                     ShortNumber(max_diff_s));
  }
  if (!std::isfinite(offset_s)) throw InputError("--offset must be finite");
}

std::vector<IndexPair> AssociateStamps(const std::vector<double>& gt_stamps_s,
                                       const std::vector<double>& est_stamps_s,
                                       const StampAssociationOptions& options) {
  options.Validate();
  CheckIncreasing(gt_stamps_s, "ground-truth");
  CheckIncreasing(est_stamps_s, "estimate");

  std::vector<IndexPair> pairs;
  for (const auto& [g, e] : AssociateNearestStamps(gt_stamps_s, est_stamps_s, options.max_diff_s, options.offset_s)) {
    pairs.push_back({static_cast<int>(g), static_cast<int>(e)});
  }
  return pairs;
}

std::vector<double> Stamps(const Trajectory& trajectory) {
  std::vector<double> stamps;
  stamps.reserve(trajectory.size());
  for (const StampedPose& pose : trajectory) stamps.push_back(pose.timestamp_s);
  return stamps;
}

std::vector<IndexPair> AssociateTrajectories(const Trajectory& gt, const Trajectory& est,
                                             const StampAssociationOptions& options) {
  return AssociateStamps(Stamps(gt), Stamps(est), options);
}

}  // namespace dynorb
