#include "dynorb/eval/rpe.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "dynorb/core/angles.h"
#include "dynorb/core/error.h"
#include "dynorb/eval/association.h"
#include "dynorb/eval/text_format.h"

namespace dynorb {
namespace {

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  const double lower = *std::max_element(values.begin(), values.begin() + mid);
  return 0.5 * (lower + upper);
}

// Differences of consecutive stamps.
std::vector<double> Intervals(const std::vector<double>& stamps) {
  std::vector<double> intervals;
  for (size_t k = 0; k + 1 < stamps.size(); ++k) intervals.push_back(stamps[k + 1] - stamps[k]);
  return intervals;
}

}  // namespace

void RpeOptions::Validate() const {
  if (!(delta_s > 0.0) || !std::isfinite(delta_s)) {
    throw InputError("--rpe-delta must be a positive number of seconds, got " +
                     ShortNumber(delta_s));
  }
  if (!std::isfinite(offset_s)) throw InputError("--offset must be finite");
  if (!(scale > 0.0) || !std::isfinite(scale)) throw InputError("RPE scale must be positive");
}

size_t ClosestIndex(const std::vector<double>& sorted_stamps, double t) {
  // evaluate_rpe.py's find_closest_index, step by step: a bisection that keeps the first visited
  // stamp strictly closer than the best so far (starting from index 0), so an exact tie goes to
  // whichever of the two stamps the bisection visits first.
  if (sorted_stamps.empty()) return 0;
  size_t begin = 0, end = sorted_stamps.size(), best = 0;
  double difference = std::abs(sorted_stamps[0] - t);
  while (begin < end) {
    const size_t middle = (begin + end) / 2;
    if (std::abs(sorted_stamps[middle] - t) < difference) {
      difference = std::abs(sorted_stamps[middle] - t);
      best = middle;
    }
    if (t == sorted_stamps[middle]) return middle;
    if (sorted_stamps[middle] > t) {
      end = middle;
    } else {
      begin = middle + 1;
    }
  }
  return best;
}

RpeResult ComputeRpe(const Trajectory& gt, const Trajectory& est, const RpeOptions& options) {
  options.Validate();
  RpeResult result;
  if (gt.size() < 2 || est.size() < 2) return result;
  const std::vector<double> gt_stamps = Stamps(gt);
  const std::vector<double> est_stamps = Stamps(est);
  result.gt_max_time_difference_s = 2.0 * Median(Intervals(gt_stamps));

  const size_t last = est_stamps.size() - 1;
  std::vector<double> trans, rot_deg, trans_paper;
  size_t self_pairs = 0, other_pairs = 0;
  for (size_t i = 0; i < est_stamps.size(); ++i) {
    const size_t j = ClosestIndex(est_stamps, est_stamps[i] + options.delta_s);
    if (j == last) continue;
    // evaluate_rpe.py would pair pose i with itself (a perfect 0): not a pair delta_s apart.
    if (j == i) {
      ++self_pairs;
      continue;
    }
    ++other_pairs;
    const double t_i = est_stamps[i] + options.offset_s;
    const double t_j = est_stamps[j] + options.offset_s;
    const size_t gi = ClosestIndex(gt_stamps, t_i);
    const size_t gj = ClosestIndex(gt_stamps, t_j);
    if (std::abs(gt_stamps[gi] - t_i) > result.gt_max_time_difference_s ||
        std::abs(gt_stamps[gj] - t_j) > result.gt_max_time_difference_s) {
      continue;
    }
    Rigid3d a = est[i].world_from_cam.Inverse() * est[j].world_from_cam;
    a.translation *= options.scale;
    const Rigid3d b = gt[gi].world_from_cam.Inverse() * gt[gj].world_from_cam;
    const Rigid3d b_inv = b.Inverse();
    const Rigid3d e_script = a * b_inv;
    const Rigid3d e_paper = b_inv * a;
    RpePair pair;
    pair.est_i = static_cast<int>(i);
    pair.est_j = static_cast<int>(j);
    pair.gt_i = static_cast<int>(gi);
    pair.gt_j = static_cast<int>(gj);
    pair.trans_m = e_script.translation.norm();
    pair.rot_rad = RotationAngleRad(e_script.rotation);
    pair.trans_paper_form_m = e_paper.translation.norm();
    result.pairs.push_back(pair);
    trans.push_back(pair.trans_m);
    rot_deg.push_back(pair.rot_rad * kDegPerRad);
    trans_paper.push_back(pair.trans_paper_form_m);
  }
  if (other_pairs == 0 && self_pairs > 0) {
    result.no_pair_reason =
        ("RPE delta " + ShortNumber(options.delta_s) +
         " s is shorter than the estimate's frame interval (median " +
         ShortNumber(Median(Intervals(est_stamps))) + " s): the pose closest to " +
         ShortNumber(options.delta_s) +
         " s after each pose is the pose itself, so there is no pose pair; use a "
         "longer --rpe-delta");
  }
  result.trans_m = Summarize(std::move(trans));
  result.rot_deg = Summarize(std::move(rot_deg));
  result.trans_paper_form_m = Summarize(std::move(trans_paper));
  return result;
}

}  // namespace dynorb
