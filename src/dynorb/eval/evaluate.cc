#include "dynorb/eval/evaluate.h"

#include <cmath>
#include <cstdio>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

template <typename... Args>
std::string Format(const char* fmt, Args... args) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), fmt, args...);
  return buf;
}

}  // namespace

void EvalOptions::Validate() const {
  association.Validate();
  RpeOptions rpe;
  rpe.delta_s = rpe_delta_s;
  rpe.Validate();
  CoverageOptions coverage;
  coverage.window_s = coverage_window_s;
  coverage.Validate();
}

EvalResult EvaluateTrajectories(const Trajectory& gt, const Trajectory& est,
                                const EvalOptions& options) {
  options.Validate();
  if (gt.empty()) throw InputError("ground-truth trajectory is empty");
  if (est.empty()) throw InputError("estimated trajectory is empty");
  EvalResult result;
  result.options = options;
  result.gt_poses = static_cast<int>(gt.size());
  result.est_poses = static_cast<int>(est.size());

  const std::vector<IndexPair> pairs = AssociateTrajectories(gt, est, options.association);
  const std::string max_diff_name = options.cli_hints ? "--max-diff " : "";
  if (pairs.empty()) {
    throw InputError(
        "no estimate pose has a ground-truth pose within " + max_diff_name +
        Format("%.4g s: ground truth spans [%.6f, %.6f], estimate spans [%.6f, %.6f] (offset %g "
               "s). Wrong files, or a time offset?",
               options.association.max_diff_s, gt.front().timestamp_s, gt.back().timestamp_s,
               est.front().timestamp_s, est.back().timestamp_s, options.association.offset_s));
  }
  if (options.alignment != AlignmentMode::kNone && pairs.size() < 3) {
    throw InputError("only " + std::to_string(pairs.size()) + " associated pose pair(s); " +
                     (options.cli_hints
                          ? "--align " + std::string(ToString(options.alignment)) +
                                " needs at least 3 (check --max-diff, or use --align none)"
                          : "the alignment needs at least 3"));
  }
  result.ate = ComputeAte(gt, est, pairs, options.alignment);

  CoverageOptions coverage_options;
  coverage_options.window_s = options.coverage_window_s;
  coverage_options.offset_s = options.association.offset_s;
  result.coverage = ComputeCoverage(gt, est, pairs, coverage_options);

  RpeOptions rpe_options;
  rpe_options.delta_s = options.rpe_delta_s;
  rpe_options.offset_s = options.association.offset_s;
  rpe_options.scale = result.ate.gt_from_est.scale;
  result.rpe = ComputeRpe(gt, est, rpe_options);

  if (result.coverage.fraction < options.coverage_warning_below) {
    result.warnings.push_back(Format(
        "coverage %.1f%% < %.0f%%: the estimate covers only part of the ground-truth time span "
        "(longest gap %.2f s, %.2f s after the first ground-truth pose); ATE/RPE describe the "
        "covered "
        "part only",
        100.0 * result.coverage.fraction, 100.0 * options.coverage_warning_below,
        result.coverage.longest_gap_s,
        result.coverage.longest_gap_start_s - result.coverage.gt_begin_s));
  }
  const int unmatched = result.est_poses - static_cast<int>(pairs.size());
  if (unmatched > 0 && unmatched * 20 > result.est_poses) {
    result.warnings.push_back(std::to_string(unmatched) + " of " +
                              std::to_string(result.est_poses) +
                              " estimate poses have no ground truth within " + max_diff_name +
                              Format("%.4g s and are ignored", options.association.max_diff_s));
  }
  const bool shorter_than_delta =
      est.back().timestamp_s - est.front().timestamp_s < options.rpe_delta_s;
  if (!result.rpe.no_pair_reason.empty()) {
    result.warnings.push_back("RPE not available: " + result.rpe.no_pair_reason);
  } else if (result.rpe.pairs.empty() &&
             (options.warn_rpe_shorter_than_delta || !shorter_than_delta)) {
    result.warnings.push_back(
        Format("RPE not available: no estimate pose pair %.3g s apart with ground truth",
               options.rpe_delta_s));
  }
  return result;
}

}  // namespace dynorb
