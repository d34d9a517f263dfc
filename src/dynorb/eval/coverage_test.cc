#include "dynorb/eval/coverage.h"

#include <gtest/gtest.h>

#include "dynorb/eval/evaluate.h"
#include "dynorb/eval/test_util.h"

namespace dynorb {
namespace {

using testing_util::Wiggle;

EvalResult Evaluate(const Trajectory& gt, const Trajectory& est) {
  return EvaluateTrajectories(gt, est, EvalOptions());
}

bool HasWarning(const EvalResult& r, const std::string& text) {
  for (const std::string& w : r.warnings) {
    if (w.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(Coverage, FullWhenEveryFrameIsPresent) {
  const Trajectory gt = Wiggle(601, 30.0);
  const EvalResult r = Evaluate(gt, gt);
  EXPECT_DOUBLE_EQ(r.coverage.fraction, 1.0);
  EXPECT_NEAR(r.coverage.gt_span_s, 20.0, 1e-9);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(Coverage, SingleDroppedFramesAreForgiven) {
  const Trajectory gt = Wiggle(601, 30.0);
  Trajectory est;
  for (size_t k = 0; k < gt.size(); ++k) {
    if (k % 10 != 5) est.push_back(gt[k]);
  }
  EXPECT_DOUBLE_EQ(Evaluate(gt, est).coverage.fraction, 1.0);
}

TEST(Coverage, LostTrackingIsCountedAndWarned) {
  // 30 Hz over 20 s; the estimate is missing (10 s, 12 s): the gap between the neighbouring poses
  // is G = t(360) - t(300) = 2 s; it loses G - 2 x 0.05 s.
  const Trajectory gt = Wiggle(601, 30.0);
  Trajectory est;
  for (size_t k = 0; k < gt.size(); ++k) {
    if (k <= 300 || k >= 360) est.push_back(gt[k]);
  }
  const EvalResult r = Evaluate(gt, est);
  const double gap = gt[360].timestamp_s - gt[300].timestamp_s;
  EXPECT_NEAR(r.coverage.fraction, 1.0 - (gap - 0.1) / 20.0, 1e-9);
  EXPECT_NEAR(r.coverage.longest_gap_s, gap - 0.1, 1e-9);
  EXPECT_NEAR(r.coverage.longest_gap_start_s, gt[300].timestamp_s + 0.05, 1e-9);
  EXPECT_TRUE(HasWarning(r, "coverage 90.5% < 95%")) << (r.warnings.empty() ? "" : r.warnings[0]);
}

TEST(Coverage, LateStartAndEarlyEndCount) {
  const Trajectory gt = Wiggle(301, 10.0);                   // 30 s
  const Trajectory est(gt.begin() + 100, gt.begin() + 201);  // 10 s .. 20 s
  const EvalResult r = Evaluate(gt, est);
  EXPECT_NEAR(r.coverage.covered_s, 10.0 + 0.1, 1e-9);
  EXPECT_NEAR(r.coverage.fraction, 10.1 / 30.0, 1e-9);
  EXPECT_FALSE(r.warnings.empty());
}

TEST(Coverage, UnassociatedEstimatesCoverNothing) {
  const Trajectory gt = Wiggle(301, 10.0);
  Trajectory est = gt;
  for (size_t k = 150; k < est.size(); ++k) est[k].timestamp_s += 0.04;  // beyond max_diff 0.02
  const EvalResult r = Evaluate(gt, est);
  EXPECT_EQ(r.ate.stats.count, 150);
  EXPECT_LT(r.coverage.fraction, 0.52);
  EXPECT_TRUE(HasWarning(r, "have no ground truth within --max-diff"));
}

TEST(EvalWarnings, RunWordingAndShortEstimates) {
  const Trajectory gt = Wiggle(301, 10.0);  // 10 Hz, 30 s
  Trajectory est = gt;
  for (size_t k = 150; k < est.size(); ++k) est[k].timestamp_s += 0.04;
  EvalOptions run;
  run.cli_hints = false;  // The words of `dynorb run`: no --max-diff.
  const EvalResult r = EvaluateTrajectories(gt, est, run);
  EXPECT_TRUE(HasWarning(r, "have no ground truth within 0.02 s and are ignored"));
  EXPECT_FALSE(HasWarning(r, "--max-diff"));
  // 0.5 s of estimate: no pose pair 1 s apart. Warned by default, not when that is expected.
  const Trajectory short_est(gt.begin() + 10, gt.begin() + 16);
  EXPECT_TRUE(HasWarning(EvaluateTrajectories(gt, short_est, EvalOptions()), "RPE not available"));
  run.warn_rpe_shorter_than_delta = false;
  EXPECT_FALSE(HasWarning(EvaluateTrajectories(gt, short_est, run), "RPE not available"));
}

}  // namespace
}  // namespace dynorb
