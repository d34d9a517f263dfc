#include "run_report.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>

#include "build_id.h"
#include "dynorb/core/error.h"
#include "dynorb/core/stats.h"

namespace dynorb {

// "0.123", or "n/a" for an undefined ratio (null: nothing to divide by).
std::string Fraction(const nlohmann::json& value) {
  if (!value.is_number()) return "n/a";
  char text[32];
  std::snprintf(text, sizeof(text), "%.3f", value.get<double>());
  return text;
}

nlohmann::json StatsJson(const std::vector<double>& values) {
  const SummaryStats s = Summarize(values);
  return {{"mean", s.mean}, {"median", s.median}, {"p95", s.p95}, {"max", s.max}, {"count", s.count}};
}

EvalResult EvaluateAgainstGroundTruth(const Trajectory& ground_truth, const Trajectory& estimate,
                                      const std::vector<FrameRecord>& records) {
  const double begin = records.front().timestamp_s - 0.05, end = records.back().timestamp_s + 0.05;
  Trajectory cropped;
  for (const StampedPose& p : ground_truth) {
    if (p.timestamp_s >= begin && p.timestamp_s <= end) cropped.push_back(p);
  }
  if (cropped.empty() && !ground_truth.empty()) {
    char text[256];
    std::snprintf(
        text, sizeof(text),
        "groundtruth.txt has no pose within the run's frames [%.6f, %.6f]; it spans [%.6f, %.6f] "
        "(another clock or another sequence?)",
        records.front().timestamp_s, records.back().timestamp_s, ground_truth.front().timestamp_s,
        ground_truth.back().timestamp_s);
    throw InputError(text);
  }
  EvalOptions options;
  options.cli_hints = false;  // `dynorb run` has no --max-diff / --align.
  // A run shorter than the RPE step has no RPE pair by construction: nothing to warn about.
  options.warn_rpe_shorter_than_delta = false;
  return EvaluateTrajectories(cropped, estimate, options);
}

std::string FramesCsv(const std::vector<FrameRecord>& records,
                      const std::vector<int>& inliers_on_movers,
                      const std::vector<int>& new_landmarks_on_movers, size_t first_frame) {
  std::string csv =
      "frame,timestamp,state,relocalized,new_keyframe,reference_keyframe,keypoints,filtered,"
      "refilled,inliers,judged,detect_ms,filter_ms,refill_ms,describe_ms,track_ms,local_map_ms,"
      "mapping_ms,total_ms,inliers_on_movers,new_landmarks_on_movers,analysed\n";
  char line[512];
  for (size_t k = 0; k < records.size(); ++k) {
    const FrameRecord& r = records[k];
    const FrameTiming& t = r.timing;
    std::snprintf(
        line, sizeof(line),
        "%zu,%.6f,%s,%d,%d,%lld,%d,%d,%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%d,%d,%d\n",
        first_frame + static_cast<size_t>(r.id), r.timestamp_s, ToString(r.state),
        r.relocalized ? 1 : 0, r.new_keyframe ? 1 : 0,
        r.reference_keyframe == kNoKeyframe ? -1LL : static_cast<long long>(r.reference_keyframe),
        r.num_keypoints, r.num_filtered, r.num_refilled, r.num_inliers, r.judged ? 1 : 0,
        t.detect_ms, t.filter_ms, t.refill_ms, t.describe_ms, t.track_ms, t.local_map_ms,
        t.mapping_ms, t.total_ms, k < inliers_on_movers.size() ? inliers_on_movers[k] : -1,
        k < new_landmarks_on_movers.size() ? new_landmarks_on_movers[k] : -1, r.analysed ? 1 : 0);
    csv += line;
  }
  return csv;
}

nlohmann::json BuildRunStats(const System& system, const RunSummaryInputs& inputs,
                             const std::optional<EvalResult>& evaluation) {
  const std::vector<FrameRecord>& records = system.records();
  int tracked = 0, lost_episodes = 0, relocalizations = 0, keyframes_inserted = 0;
  long long dynamic_votes = 0, erased_as_dynamic = 0;
  bool was_lost = false;
  std::map<std::string, std::vector<double>> filter_stages;  // Name order: deterministic JSON.
  std::vector<double> refill, refilled;
  std::vector<double> detect, filter, describe, track, local_map, mapping, total, latency, keypoints, filtered, inliers;
  for (const FrameRecord& r : records) {
    tracked += r.pose_valid ? 1 : 0;
    const bool lost = r.state == TrackingState::kLost;
    if (lost && !was_lost) ++lost_episodes;
    was_lost = lost;
    relocalizations += r.relocalized ? 1 : 0;
    keyframes_inserted += r.new_keyframe ? 1 : 0;
    dynamic_votes += r.dynamic_votes;
    erased_as_dynamic += r.erased_as_dynamic;
    detect.push_back(r.timing.detect_ms);
    filter.push_back(r.timing.filter_ms);
    refill.push_back(r.timing.refill_ms);
    refilled.push_back(r.num_refilled);
    for (const auto& [stage, ms] : r.timing.filter_stages_ms) filter_stages[stage].push_back(ms);
    describe.push_back(r.timing.describe_ms);
    track.push_back(r.timing.track_ms);
    local_map.push_back(r.timing.local_map_ms);
    mapping.push_back(r.timing.mapping_ms);
    total.push_back(r.timing.total_ms);
    latency.push_back(r.timing.latency_ms);
    keypoints.push_back(r.num_keypoints);
    if (r.judged) filtered.push_back(r.num_filtered);  // A withheld first frame was not filtered.
    inliers.push_back(r.num_inliers);
  }
  std::vector<double> mapper_ms, ba_ms;
  for (const MapperStepStats& m : system.mapper_stats()) {
    mapper_ms.push_back(m.total_ms);
    ba_ms.push_back(m.bundle_adjustment_ms);
  }
  const double n = std::max<size_t>(1, records.size());
  nlohmann::json j;
  j["dataset"] = inputs.dataset;
  j["config"] = inputs.config;
  j["mode"] = inputs.mode;
  j["build_id"] = BuildId();
  j["run_mode"] = inputs.run_mode;
  j["pipeline"] = inputs.pipeline;
  j["pipeline_depth"] = inputs.pipeline_depth;
  j["front_end_threads"] = inputs.front_end_threads;
  // Frames decoded before the run (--preload): the timings then exclude PNG decoding competing
  // for the cores, as with a live camera.
  j["preload"] = inputs.preload;
  if (inputs.preload) j["preload_seconds"] = inputs.preload_seconds;
  j["seed"] = inputs.seed;
  j["first_frame"] = inputs.first_frame;
  j["frames"] = records.size();
  j["tracked_frames"] = tracked;
  j["tracked_fraction"] = tracked / n;
  j["lost_episodes"] = lost_episodes;
  j["relocalizations"] = relocalizations;
  j["keyframes_inserted"] = keyframes_inserted;
  j["keyframes"] = system.NumKeyframes();
  j["landmarks"] = system.NumLandmarks();
  j["landmarks_erased_as_dynamic"] = {{"erased", erased_as_dynamic},
                                      {"votes", dynamic_votes},
                                      {"definition",
                                       "landmarks of the local map observed moving (projecting "
                                       "next to a keypoint the filter saw move, at that "
                                       "keypoint's depth; votes: one per landmark and frame), "
                                       "erased after tracking.dynamic_votes_to_erase votes "
                                       "with no static inlier match in between"}};
  // Loop closing: every keyframe where a loop was detected, whether the check confirmed it.
  nlohmann::json loops = nlohmann::json::array();
  int loops_closed = 0;
  for (const LoopStepStats& l : system.loop_stats()) {
    nlohmann::json e = {
        {"keyframe", l.keyframe}, {"closed", l.closed}, {"agreement", l.agreement}, {"ms", l.ms}};
    if (l.closed) {
      ++loops_closed;
      e["loop_keyframe"] = l.loop_keyframe;
      e["inliers"] = l.inliers;
      e["fused"] = l.fused;
      e["correction_m"] = l.correction_m;
      e["correction_deg"] = l.correction_deg;
    }
    loops.push_back(e);
  }
  j["loops_closed"] = loops_closed;
  j["loop_detections"] = loops;
  // Global bundle adjustments after the loops (committed: not stopped by a newer loop).
  nlohmann::json gbas = nlohmann::json::array();
  for (const GlobalBaStats& g : system.global_ba_stats()) {
    gbas.push_back({{"committed", g.committed},
                    {"keyframes", g.keyframes},
                    {"landmarks", g.landmarks},
                    {"observations", g.observations},
                    {"outlier_observations", g.outlier_observations},
                    {"removed_observations", g.removed_observations},
                    {"propagated_keyframes", g.propagated_keyframes},
                    {"propagated_landmarks", g.propagated_landmarks},
                    {"initial_cost", g.initial_cost},
                    {"final_cost", g.final_cost},
                    {"ms", g.ms}});
  }
  j["global_bundle_adjustments"] = gbas;
  j["wall_seconds"] = inputs.wall_seconds;
  if (inputs.overlay_write_seconds > 0.0) j["overlay_write_seconds"] = inputs.overlay_write_seconds;
  j["wall_hz"] = records.size() / std::max(1e-9, inputs.wall_seconds);
  // CPU of every thread over the same span (without --preload it includes decoding the PNGs): what
  // a mode costs the machine, and with wall_seconds how many cores the run kept busy. It moves with
  // the host's speed as the wall clock does.
  j["cpu_seconds"] = inputs.cpu_seconds;
  j["cpu_ms_per_frame"] = 1000.0 * inputs.cpu_seconds / std::max<double>(1.0, static_cast<double>(records.size()));
  j["keypoints_per_frame"] = StatsJson(keypoints);
  j["filtered_keypoints_per_frame"] = StatsJson(filtered);
  j["refilled_keypoints_per_frame"] = StatsJson(refilled);  // 0 on frames without a refill.
  // Frames the keypoint filter analysed; the others carried its earlier result (frames.csv
  // `analysed`; every frame without a filter).
  j["filter_analysed_frames"] = std::count_if(records.begin(), records.end(),
                                              [](const FrameRecord& r) { return r.analysed; });
  j["inliers_per_frame"] = StatsJson(inliers);
  j["timing_ms"] = {{"detect", StatsJson(detect)},     {"filter", StatsJson(filter)},     {"refill", StatsJson(refill)},
                    {"describe", StatsJson(describe)}, {"track", StatsJson(track)},
                    {"local_map", StatsJson(local_map)}, {"mapping_inline", StatsJson(mapping)},
                    {"frame_total", StatsJson(total)}, {"frame_latency", StatsJson(latency)},
                    {"mapper_per_keyframe", StatsJson(mapper_ms)},
                    {"local_ba_per_keyframe", StatsJson(ba_ms)}};
  if (!filter_stages.empty()) {
    nlohmann::json stages = nlohmann::json::object();
    for (const auto& [stage, values] : filter_stages) {
      stages[stage] = StatsJson(values);
      // The frames the stage ran on (e.g. semantic's detector on its schedule): it took > 0 ms.
      stages[stage]["frames_run"] =
          std::count_if(values.begin(), values.end(), [](double ms) { return ms > 0.0; });
    }
    j["timing_ms"]["filter_stages"] = stages;
  }
  if (evaluation) {
    const EvalResult& e = *evaluation;
    j["ate"] = {{"rmse_m", e.ate.stats.rmse}, {"mean_m", e.ate.stats.mean}, {"median_m", e.ate.stats.median},
                {"max_m", e.ate.stats.max}, {"pairs", e.ate.stats.count}, {"alignment", "se3"}};
    // No pair (a run shorter than the RPE delta): null, not a perfect 0.
    const bool rpe = e.rpe.trans_m.count > 0;
    j["rpe"] = {{"trans_rmse_m_per_s", rpe ? nlohmann::json(e.rpe.trans_m.rmse) : nlohmann::json()},
                {"rot_rmse_deg_per_s", rpe ? nlohmann::json(e.rpe.rot_deg.rmse) : nlohmann::json()},
                {"pairs", e.rpe.trans_m.count}};
    j["coverage"] = e.coverage.fraction;
  }
  return j;
}

std::string FormatRunSummary(const nlohmann::json& stats) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof(line), "frames            %d (tracked %.1f %%, %d lost episodes, %d relocalizations)\n",
                stats["frames"].get<int>(), 100.0 * stats["tracked_fraction"].get<double>(),
                stats["lost_episodes"].get<int>(), stats["relocalizations"].get<int>());
  out << line;
  std::snprintf(
      line, sizeof(line), "map               %d keyframes, %d landmarks, %d loops closed\n",
      stats["keyframes"].get<int>(), stats["landmarks"].get<int>(), stats.value("loops_closed", 0));
  out << line;
  // With ground-truth masks: the share of the map's landmarks made on dynamic objects.
  if (stats.contains("map_landmarks_on_dynamic_objects")) {
    const nlohmann::json& m = stats["map_landmarks_on_dynamic_objects"];
    if (m.value("origin_known", 0) > 0) {
      std::snprintf(
          line, sizeof(line),
          "map vs masks      %.1f %% of the landmarks made on dynamic objects (%lld of %lld)\n",
          100.0 * m["fraction"].get<double>(), m["made_on_dynamic_objects"].get<long long>(),
          m["origin_known"].get<long long>());
      out << line;
    }
  }
  std::snprintf(line, sizeof(line), "time per frame    %.1f ms mean, %.1f ms p95 (%.1f Hz wall)\n",
                stats["timing_ms"]["frame_total"]["mean"].get<double>(),
                stats["timing_ms"]["frame_total"]["p95"].get<double>(), stats["wall_hz"].get<double>());
  out << line;
  if (stats.contains("ate")) {
    std::snprintf(line, sizeof(line), "ATE RMSE          %.4f m (%d pairs, coverage %.1f %%)\n",
                  stats["ate"]["rmse_m"].get<double>(), stats["ate"]["pairs"].get<int>(),
                  100.0 * stats["coverage"].get<double>());
    out << line;
    const nlohmann::json& rpe = stats["rpe"];
    if (rpe["trans_rmse_m_per_s"].is_number() && rpe["rot_rmse_deg_per_s"].is_number()) {
      std::snprintf(line, sizeof(line), "RPE (1 s)         %.4f m/s, %.3f deg/s\n",
                    rpe["trans_rmse_m_per_s"].get<double>(),
                    rpe["rot_rmse_deg_per_s"].get<double>());
      out << line;
    } else {
      out << "RPE (1 s)         n/a (no pose pair 1 s apart)\n";
    }
  }
  // Keypoint labels against the ground-truth masks (synthetic sequences), objects moving at the
  // frame, when the mode removed any: by the keypoint's centre pixel, and counting the corners
  // of an object's outline (FAST circle on the object) as the object's.
  if (stats.contains("dynamic_keypoints") && stats["dynamic_keypoints"].contains("moving_now")) {
    const nlohmann::json& now = stats["dynamic_keypoints"]["moving_now"];
    if (now.value("true_positive", 0) + now.value("false_positive", 0) > 0 &&
        now.contains("support")) {
      std::snprintf(
          line, sizeof(line),
          "moving keypoints  precision %s, recall %s (centre on the mask); outline corners "
          "counted: %s, %s\n",
          Fraction(now["precision"]).c_str(), Fraction(now["recall"]).c_str(),
          Fraction(now["support"]["precision"]).c_str(),
          Fraction(now["support"]["recall"]).c_str());
      out << line;
    }
  }
  if (stats.contains("warnings")) {
    for (const auto& warning : stats["warnings"])
      out << "warning           " << warning.get<std::string>() << "\n";
  }
  return out.str();
}

}  // namespace dynorb
