// Statistics and summaries of a `dynorb run`: stats.json content and the printed summary.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "dynorb/eval/evaluate.h"
#include "dynorb/system/system.h"

namespace dynorb {

struct RunSummaryInputs {
  std::string dataset, config, mode, run_mode;
  uint64_t seed = 0;
  size_t first_frame = 0;
  double wall_seconds = 0.0;
};

// ATE/RPE of the estimate against the sequence's ground truth, restricted to the time span of the
// processed frames (so a --frames subset is not charged for frames it was not given).
EvalResult EvaluateAgainstGroundTruth(const Trajectory& ground_truth, const Trajectory& estimate,
                                      const std::vector<FrameRecord>& records);

nlohmann::json BuildRunStats(const System& system, const RunSummaryInputs& inputs,
                             const std::optional<EvalResult>& evaluation);

// frames.csv: one line per processed frame (state, keyframe, keypoint counts, inliers, stage
// times), with a header line. For finding where a run went wrong (docs/slam_core.md "Outputs").
std::string FramesCsv(const std::vector<FrameRecord>& records);

// A few aligned lines for stdout.
std::string FormatRunSummary(const nlohmann::json& stats);

}  // namespace dynorb
