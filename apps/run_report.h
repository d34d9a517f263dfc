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
  bool pipeline = false;  // RunRequest::pipeline
  int pipeline_depth = 0;  // RunRequest::pipeline_depth when pipelined, else 0
  int front_end_threads = 0;  // RunRequest::front_end_threads when pipelined, else 0
  size_t first_frame = 0;
  double wall_seconds = 0.0;     // from the first frame's processing (after a preload)
  double cpu_seconds = 0.0;      // CPU time of the process (all threads) over the same span
  // Writing --save-overlays' files (wall time): inside wall_seconds; its CPU time (the writing
  // thread's) is taken off cpu_seconds.
  double overlay_write_seconds = 0.0;
  bool preload = false;          // RunRequest::preload
  double preload_seconds = 0.0;  // decoding every frame before the run (with preload)
};

// ATE/RPE of the estimate against the sequence's ground truth, restricted to the time span of the
// processed frames (so a --frames subset is not charged for frames it was not given).
EvalResult EvaluateAgainstGroundTruth(const Trajectory& ground_truth, const Trajectory& estimate,
                                      const std::vector<FrameRecord>& records);

nlohmann::json BuildRunStats(const System& system, const RunSummaryInputs& inputs,
                             const std::optional<EvalResult>& evaluation);

// {mean, median, p95, max, count} of per-frame values, as stats.json writes them.
nlohmann::json StatsJson(const std::vector<double>& values);

// frames.csv: one line per processed frame (state, keyframe, keypoint counts, inliers, stage
// times), with a header line. For finding where a run went wrong (docs/slam_core.md "Outputs").
// `inliers_on_movers` / `new_landmarks_on_movers` (empty: no masks): per record, pose inliers and
// newly created landmarks on objects moving at that frame (centre pixel on the ground-truth mask),
// written as the last two columns (-1 without masks, or without a mask at that frame).
// `frame` is the frame's index in the sequence, `first_frame` + the record's id (the overlays'
// file names use the same index).
std::string FramesCsv(const std::vector<FrameRecord>& records,
                      const std::vector<int>& inliers_on_movers = {},
                      const std::vector<int>& new_landmarks_on_movers = {}, size_t first_frame = 0);

// A few aligned lines for stdout.
std::string FormatRunSummary(const nlohmann::json& stats);

}  // namespace dynorb
