// EvaluateTrajectories: the whole `dynorb eval` computation on in-memory trajectories —
// association, ATE (with alignment), coverage and RPE — as one call. No file I/O (the CLI reads
// and writes files). Definitions: association.h, ate.h, coverage.h, rpe.h, docs/evaluation.md.
// Pure function, thread-safe.
#pragma once

#include <string>
#include <vector>

#include "dynorb/core/trajectory.h"
#include "dynorb/eval/ate.h"
#include "dynorb/eval/coverage.h"
#include "dynorb/eval/rpe.h"

namespace dynorb {

struct EvalOptions {
  StampAssociationOptions association;            // --max-diff, --offset
  AlignmentMode alignment = AlignmentMode::kSe3;  // --align
  double rpe_delta_s = 1.0;                       // --rpe-delta
  double coverage_window_s = 0.05;                // see coverage.h
  double coverage_warning_below = 0.95;           // warn when coverage fraction is lower
  // Messages name `dynorb eval`'s options (--max-diff, --align) as what to change; false: the
  // same facts without them (the evaluation inside `dynorb run`, which has no such options).
  bool cli_hints = true;
  // Warn that the RPE is not available also when the estimate spans less than rpe_delta_s (no
  // pose pair by construction); false: only when a longer estimate has none (its gaps).
  bool warn_rpe_shorter_than_delta = true;
  void Validate() const;                          // throws InputError
};

struct EvalResult {
  EvalOptions options;
  int gt_poses = 0;
  int est_poses = 0;
  AteResult ate;
  Coverage coverage;
  RpeResult rpe;                      // RPE uses the sim3 scale when alignment is sim3
  std::vector<std::string> warnings;  // human-readable, e.g. low coverage
};

// Throws InputError when the trajectories do not overlap in time (no associated pair) or when
// alignment has fewer than 3 pairs.
EvalResult EvaluateTrajectories(const Trajectory& gt, const Trajectory& est,
                                const EvalOptions& options);

}  // namespace dynorb
