#include "bench_tables.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <set>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// Value of one run, or nothing (metric absent, e.g. no ground truth).
using Metric = std::function<std::optional<double>(const Json& stats)>;

Metric Path(std::vector<std::string> keys, double scale = 1.0) {
  return [keys, scale](const Json& stats) -> std::optional<double> {
    const Json* node = &stats;
    for (const std::string& k : keys) {
      if (!node->is_object() || !node->contains(k)) return std::nullopt;
      node = &(*node)[k];
    }
    if (!node->is_number()) return std::nullopt;
    return node->get<double>() * scale;
  };
}

// RPE of a run, or nothing when it had no pair (a sequence shorter than the RPE delta).
Metric Rpe(const std::string& key) {
  const Metric value = Path({"rpe", key}), pairs = Path({"rpe", "pairs"});
  return [value, pairs](const Json& stats) -> std::optional<double> {
    const std::optional<double> n = pairs(stats);
    if (!n || *n <= 0) return std::nullopt;
    return value(stats);
  };
}

std::string Fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", digits, v);
  return text;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// "median" or "median [min-max]".
std::string Cell(const std::vector<double>& values, int digits, const std::string& suffix = "") {
  if (values.empty()) return "-";
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  std::string text = Fixed(Median(values), digits) + suffix;
  if (values.size() > 1) text += " [" + Fixed(*lo, digits) + "-" + Fixed(*hi, digits) + "]";
  return text;
}

// A mask id of stats' by_object ("3"), or nothing for any other key.
std::optional<int> MaskId(const std::string& key) {
  int id = 0;
  const char* end = key.data() + key.size();
  const auto [last, error] = std::from_chars(key.data(), end, id);
  if (error != std::errc() || last != end || id < 0) return std::nullopt;
  return id;
}

double Mean(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values) sum += v;
  return values.empty() ? 0.0 : sum / static_cast<double>(values.size());
}

// "mean [min-max]" with a range, "mean" for one value, "-" for none.
std::string MeanCell(const std::vector<double>& values, int digits, bool range = true) {
  if (values.empty()) return "-";
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  std::string text = Fixed(Mean(values), digits);
  if (range && values.size() > 1)
    text += " [" + Fixed(*lo, digits) + "-" + Fixed(*hi, digits) + "]";
  return text;
}

class Runs {
 public:
  explicit Runs(const Json& results) {
    for (const Json& run : results["runs"]) {
      if (run.value("status", "") != "ok" || !run.contains("stats")) continue;
      by_key_[{run["sequence"].get<std::string>(), run["mode"].get<std::string>()}]
             [run["seed"].get<uint64_t>()] = &run["stats"];
    }
  }
  // seed -> value for (sequence, mode).
  std::map<uint64_t, double> Values(const std::string& seq, const std::string& mode,
                                    const Metric& metric) const {
    std::map<uint64_t, double> out;
    const auto it = by_key_.find({seq, mode});
    if (it == by_key_.end()) return out;
    for (const auto& [seed, stats] : it->second) {
      if (const std::optional<double> v = metric(*stats)) out[seed] = *v;
    }
    return out;
  }
  // The stats of every seed's run of (sequence, mode).
  std::vector<const Json*> Stats(const std::string& seq, const std::string& mode) const {
    std::vector<const Json*> out;
    const auto it = by_key_.find({seq, mode});
    if (it == by_key_.end()) return out;
    for (const auto& [seed, stats] : it->second) out.push_back(stats);
    return out;
  }
  std::vector<double> List(const std::string& seq, const std::string& mode,
                           const Metric& metric) const {
    std::vector<double> out;
    for (const auto& [seed, v] : Values(seq, mode, metric)) out.push_back(v);
    return out;
  }
  // Per-seed ratios a/b over the seeds both have.
  std::vector<double> Ratios(const std::string& seq_a, const std::string& mode_a,
                             const std::string& seq_b, const std::string& mode_b,
                             const Metric& metric) const {
    const auto a = Values(seq_a, mode_a, metric), b = Values(seq_b, mode_b, metric);
    std::vector<double> out;
    for (const auto& [seed, va] : a) {
      const auto it = b.find(seed);
      if (it != b.end() && it->second > 0) out.push_back(va / it->second);
    }
    return out;
  }

 private:
  std::map<std::pair<std::string, std::string>, std::map<uint64_t, const Json*>> by_key_;
};

struct Names {
  std::vector<std::string> sequences, modes;
  std::map<std::string, std::string> twin_of, tum_name;  // sequence -> ...
  std::map<std::string, std::string> view_loss_of;       // view-loss reference -> dynamic
  std::map<std::string, std::string> view_loss_ref;      // dynamic -> its view-loss reference
  std::string view_loss_mode;                            // its mode's label; empty: none

  // Whether (sequence, mode) is a planned run: a view-loss reference runs only its own mode.
  bool Planned(const std::string& sequence, const std::string& mode) const {
    return (view_loss_of.count(sequence) > 0) ==
           (!view_loss_mode.empty() && mode == view_loss_mode);
  }
};

Names ReadNames(const Json& results) {
  Names n;
  for (const Json& s : results["suite"]["sequences"]) {
    const std::string name = s["name"].get<std::string>();
    n.sequences.push_back(name);
    if (!s.value("twin_of", "").empty()) n.twin_of[name] = s["twin_of"].get<std::string>();
    if (!s.value("tum_name", "").empty()) n.tum_name[name] = s["tum_name"].get<std::string>();
    if (!s.value("view_loss_of", "").empty()) {
      n.view_loss_of[name] = s["view_loss_of"].get<std::string>();
      n.view_loss_ref[s["view_loss_of"].get<std::string>()] = name;
    }
  }
  for (const Json& m : results["suite"]["modes"]) {
    n.modes.push_back(m["label"].get<std::string>());
    if (m.value("view_loss", false)) n.view_loss_mode = n.modes.back();
  }
  return n;
}

BenchTable MetricTable(const Runs& runs, const Names& names, std::string id, std::string title,
                       std::string note, const Metric& metric, int digits) {
  BenchTable t{std::move(id), std::move(title), std::move(note), {"sequence"}, {}};
  for (const std::string& m : names.modes) t.header.push_back(m);
  for (const std::string& s : names.sequences) {
    std::vector<std::string> row{s};
    for (const std::string& m : names.modes) row.push_back(Cell(runs.List(s, m, metric), digits));
    t.rows.push_back(row);
  }
  return t;
}

// One row per mode over the dynamic sequences that have a static twin and all their seeds.
BenchTable SummaryTable(const Runs& runs, const Names& names, size_t num_seeds) {
  BenchTable t{
      "summary",
      "Summary per mode",
      "Over every dynamic sequence that has a static twin and every seed (runs: how "
      "many of those finished with an ATE; the other columns use those only): the mean ATE; "
      "the robustness ratio (table below) as median [min-max] and how many are <= 1.3; "
      "the time per frame as mean [min-max]; the speed ratio to plain as median "
      "[min-max]; of the final maps' landmarks with a known origin, the share made on "
      "dynamic objects, all runs pooled (in brackets per object id of the masks; "
      "synthetic sequences: 1-3 people, 4 the pushed box, 5 the desk item).",
      {"mode", "runs", "mean ATE [m]", "ATE ratio to twin", "ratio <= 1.3", "ms per frame",
       "speed ratio to plain", "landmarks on dynamic objects [%] (per object)"},
      {}};
  const bool has_plain =
      std::find(names.modes.begin(), names.modes.end(), "plain") != names.modes.end();
  const Metric ate = Path({"ate", "rmse_m"});
  const Metric ms = Path({"timing_ms", "frame_total", "mean"});
  const Metric made = Path({"map_landmarks_on_dynamic_objects", "made_on_dynamic_objects"});
  const Metric known = Path({"map_landmarks_on_dynamic_objects", "origin_known"});
  for (const std::string& m : names.modes) {
    if (m == names.view_loss_mode) continue;  // runs on twins only
    std::vector<double> ates, ratios, times, speed;
    double made_sum = 0.0, known_sum = 0.0;
    std::map<int, double> by_object_sum;  // mask id -> landmarks made on it
    for (const auto& [twin, dynamic] : names.twin_of) {
      const auto append = [](std::vector<double>* to, const std::vector<double>& from) {
        to->insert(to->end(), from.begin(), from.end());
      };
      append(&ates, runs.List(dynamic, m, ate));
      append(&ratios, runs.Ratios(dynamic, m, twin, m, ate));
      append(&times, runs.List(dynamic, m, ms));
      if (has_plain) append(&speed, runs.Ratios(dynamic, m, dynamic, "plain", ms));
      for (const Json* stats : runs.Stats(dynamic, m)) {
        const std::optional<double> n = made(*stats), of = known(*stats);
        if (!n || !of) continue;
        made_sum += *n;
        known_sum += *of;
        const Json& by_object =
            (*stats)["map_landmarks_on_dynamic_objects"].value("by_object", Json::object());
        for (const auto& [key, count] : by_object.items()) {
          const std::optional<int> id = MaskId(key);
          if (id && count.is_number()) by_object_sum[*id] += count.get<double>();
        }
      }
    }
    std::string landmarks = "-";
    if (known_sum > 0.0) {
      landmarks = Fixed(100.0 * made_sum / known_sum, 2);
      std::string parts;
      for (const auto& [id, count] : by_object_sum) {
        parts += (parts.empty() ? "" : ", ") + std::to_string(id) + ": " +
                 Fixed(100.0 * count / known_sum, 2);
      }
      if (!parts.empty()) landmarks += " (" + parts + ")";
    }
    const auto within =
        std::count_if(ratios.begin(), ratios.end(), [](double v) { return v <= 1.3; });
    t.rows.push_back(
        {m, std::to_string(ates.size()) + " of " + std::to_string(names.twin_of.size() * num_seeds),
         MeanCell(ates, 4, /*range=*/false), Cell(ratios, 2),
         ratios.empty() ? "-" : std::to_string(within) + " of " + std::to_string(ratios.size()),
         MeanCell(times, 1), Cell(speed, 2, "x"), landmarks});
  }
  return t;
}

BenchTable PublishedTable(const Runs& runs, const Names& names, const Json& published) {
  BenchTable t{
      "published",
      "Real TUM sequences: ATE RMSE [m] next to published numbers",
      "Our rows: median over the repeats. Published rows: values as printed in the cited source "
      "(bench/published_results.json); other machines, other runs, often the median of 5 runs.",
      {"system"},
      {}};
  std::vector<std::pair<std::string, std::string>> columns;  // (tum name, our sequence)
  for (const std::string& s : names.sequences) {
    if (names.tum_name.count(s)) columns.push_back({names.tum_name.at(s), s});
  }
  for (const auto& c : columns) t.header.push_back(c.first);
  t.header.push_back("source");
  const Metric ate = Path({"ate", "rmse_m"});
  for (const std::string& m : names.modes) {
    if (m == names.view_loss_mode) continue;  // runs on synthetic twins only
    std::vector<std::string> row{"dynorb " + m};
    for (const auto& c : columns) {
      const std::vector<double> v = runs.List(c.second, m, ate);
      row.push_back(v.empty() ? "-" : Fixed(Median(v), 3));
    }
    row.push_back("this run");
    t.rows.push_back(row);
  }
  if (published.is_object() && published.contains("systems")) {
    for (const Json& sys : published["systems"]) {
      std::vector<std::string> row{sys.value("system", "?")};
      for (const auto& c : columns) {
        const Json& values = sys["ate_rmse_m"];
        row.push_back(values.contains(c.first) ? Fixed(values[c.first].get<double>(), 4) : "-");
      }
      std::string source = sys.value("source", "");
      if (!sys.value("note", "").empty()) source += "; " + sys["note"].get<std::string>();
      if (!sys.value("verified", true)) source += " (not verified)";
      row.push_back(source);
      t.rows.push_back(row);
    }
  }
  return t;
}

// How the suite's pipelined runs split their front ends (`dynorb run --front-end-threads`;
// results written before the key existed ran on one thread).
std::string FrontEndThreadsText(const Json& suite) {
  if (!suite.value("pipeline", false)) return "";
  switch (suite.value("front_end_threads", 1)) {
    case 0: return ", 2 front-end threads with a filter (1 in plain)";
    case 2: return ", 2 front-end threads";
    default: return "";
  }
}

}  // namespace

BenchReportContent BuildBenchReport(const Json& results, const Json& published,
                                    const std::string& out_dir) {
  if (!results.is_object() || results.value("format", "") != "dynorb-bench-results/1" ||
      !results.contains("runs") || !results.contains("suite")) {
    throw InputError("not a dynorb bench results.json (format dynorb-bench-results/1 expected)");
  }
  const Runs runs(results);
  const Names names = ReadNames(results);
  BenchReportContent r;
  const Json& suite = results["suite"];
  r.title = "dynorb bench: " + suite.value("name", std::string("suite"));
  int ok = 0, failed = 0;
  for (const Json& run : results["runs"]) (run.value("status", "") == "ok" ? ok : failed)++;
  r.summary.push_back("suite: " + suite.value("file", std::string()) +
                      (suite.value("description", "").empty()
                           ? ""
                           : " - " + suite["description"].get<std::string>()));
  r.summary.push_back("generated: " + results.value("generated_utc", std::string("?")) +
                      ", run mode " + suite.value("run_mode", std::string("?")) + ", pipeline " +
                      (suite.contains("pipeline") ? (suite["pipeline"].get<bool>() ? "on" : "off") : "?") +
                      (suite.contains("pipeline_depth") && suite.value("pipeline", false)
                           ? " (depth " + std::to_string(suite["pipeline_depth"].get<int>()) + ")"
                           : "") +
                      FrontEndThreadsText(suite) +
                      (suite.value("preload", false) ? ", frames preloaded (live-camera timing)" : "") +
                      ", seeds " +
                      suite["seeds"].dump());
  r.summary.push_back("runs: " + std::to_string(ok) + " ok, " + std::to_string(failed) + " failed" +
                      (failed ? " (see results.json)" : ""));
  // The runs' own plausibility warnings (stats.json "warnings": depth scale, initialisation).
  for (const Json& run : results["runs"]) {
    if (run.value("status", "") != "ok" || !run.contains("stats")) continue;
    for (const Json& warning : run["stats"].value("warnings", Json::array())) {
      r.summary.push_back("warning: " + run.value("sequence", std::string("?")) + " / " +
                          run.value("mode", std::string("?")) + " seed " +
                          std::to_string(run.value("seed", uint64_t{0})) + ": " +
                          warning.get<std::string>());
    }
  }
  r.summary.push_back(
      "cells: median over the repeats, [min-max] when there are several; '-' = not available");

  const Metric ate = Path({"ate", "rmse_m"});
  const Metric ms = Path({"timing_ms", "frame_total", "mean"});
  if (!names.twin_of.empty())
    r.tables.push_back(SummaryTable(runs, names, suite.value("seeds", Json::array()).size()));
  r.tables.push_back(
      MetricTable(runs, names, "ate", "ATE RMSE [m]",
                  "Absolute trajectory error after SE(3) alignment to the ground truth.", ate, 4));
  // Robustness: dynamic vs static twin, paired by seed. The view-loss reference's column divides
  // its ATE by the twin's plain ATE.
  BenchTable robust{
      "robustness",
      "Robustness ratio ATE(dynamic) / ATE(static twin)",
      "Per seed, the ATE on the sequence with moving people divided by the ATE on its static twin "
      "(same camera path and noise, nothing moving); 1 = people do not hurt." +
          std::string(names.view_loss_mode.empty()
                          ? ""
                          : " Column " + names.view_loss_mode +
                                ": the twin's images with the dynamic sequence's ground-truth "
                                "masks (mode semantic, a perfect mask) over the twin's plain "
                                "ATE: what hiding part of the view alone costs."),
      {"sequence"},
      {}};
  std::vector<std::string> ratio_modes;
  for (const std::string& m : names.modes) {
    if (m != names.view_loss_mode) ratio_modes.push_back(m);
  }
  if (!names.view_loss_mode.empty()) ratio_modes.push_back(names.view_loss_mode);
  for (const std::string& m : ratio_modes) robust.header.push_back(m);
  std::vector<std::vector<double>> all_ratios(ratio_modes.size());
  for (const auto& [twin, dynamic] : names.twin_of) {
    std::vector<std::string> row{dynamic};
    for (size_t k = 0; k < ratio_modes.size(); ++k) {
      std::vector<double> ratios;
      if (ratio_modes[k] != names.view_loss_mode) {
        ratios = runs.Ratios(dynamic, ratio_modes[k], twin, ratio_modes[k], ate);
      } else if (names.view_loss_ref.count(dynamic)) {
        ratios = runs.Ratios(names.view_loss_ref.at(dynamic), ratio_modes[k], twin, "plain", ate);
      }
      all_ratios[k].insert(all_ratios[k].end(), ratios.begin(), ratios.end());
      row.push_back(Cell(ratios, 2));
    }
    robust.rows.push_back(row);
  }
  if (names.twin_of.size() > 1) {
    // Single-sequence ratios move by +-0.15 with small changes: the pooled row is the verdict.
    std::vector<std::string> pooled{"all sequences and seeds"}, within{"ratio <= 1.3"};
    for (const std::vector<double>& ratios : all_ratios) {
      pooled.push_back(Cell(ratios, 2));
      const auto within_target =
          std::count_if(ratios.begin(), ratios.end(), [](double v) { return v <= 1.3; });
      within.push_back(ratios.empty() ? "-"
                                      : std::to_string(within_target) + " of " +
                                            std::to_string(ratios.size()));
    }
    robust.rows.push_back(pooled);
    robust.rows.push_back(within);
  }
  if (!robust.rows.empty()) r.tables.push_back(robust);
  r.tables.push_back(MetricTable(runs, names, "rpe_t", "RPE translation [m/s]",
                                 "Relative pose error over 1 s.", Rpe("trans_rmse_m_per_s"), 4));
  r.tables.push_back(MetricTable(runs, names, "rpe_r", "RPE rotation [deg/s]",
                                 "Relative pose error over 1 s.", Rpe("rot_rmse_deg_per_s"), 3));
  r.tables.push_back(
      MetricTable(runs, names, "tracked", "Tracked frames [%]",
                  "Frames with a valid pose (coverage of the ground truth in results.json).",
                  Path({"tracked_fraction"}, 100.0), 1));
  r.tables.push_back(MetricTable(runs, names, "lost", "Lost episodes", "Times tracking was lost.",
                                 Path({"lost_episodes"}), 0));
  const Metric map_dynamic = Path({"map_landmarks_on_dynamic_objects", "fraction"}, 100.0);
  bool any_map_truth = false;  // Only sequences with masks have it: no table of dashes otherwise.
  for (const std::string& s : names.sequences)
    for (const std::string& m : names.modes) any_map_truth |= !runs.List(s, m, map_dynamic).empty();
  if (any_map_truth)
    r.tables.push_back(
        MetricTable(runs, names, "map_dynamic", "Map landmarks made on dynamic objects [%]",
                    "Of the final map's landmarks whose oldest observing keyframe has a "
                    "ground-truth mask (nearly all), the share whose keypoint there lay on a "
                    "dynamic object (moving at that frame or not): what each mode let into the "
                    "map (stats.json map_landmarks_on_dynamic_objects; sequences with masks).",
                    map_dynamic, 1));
  r.tables.push_back(
      MetricTable(runs, names, "ms", "Time per frame [ms] (mean)",
                  "Time the caller waited per frame (timing_ms.frame_total: feature extraction, filter, "
                  "tracking, inline mapping in sequential mode). Pipelined runs (the default) extract and "
                  "filter the next frame on a second thread meanwhile, so this is the frame-rate bound; "
                  "stats.json's frame_latency is one frame's own time.",
                  ms, 1));
  const Metric cpu = Path({"cpu_ms_per_frame"});
  r.tables.push_back(MetricTable(
      runs, names, "cpu", "CPU time per frame [ms]",
      "CPU time of every thread of the run over its frames, divided by the frames (stats.json "
      "cpu_ms_per_frame; includes PNG decoding unless the frames were preloaded): what a mode costs the "
      "machine. A run that keeps both of 2 cores busy takes about half of it per frame.",
      cpu, 1));
  const bool has_plain =
      std::find(names.modes.begin(), names.modes.end(), "plain") != names.modes.end();
  auto ratio_to_plain = [&](const std::string& id, const std::string& title, const Metric& metric) {
    if (!has_plain) return;
    BenchTable table{id, title, "Per seed on the same sequence; > 1 = slower than plain.", {"sequence"}, {}};
    for (const std::string& m : names.modes) table.header.push_back(m);
    for (const std::string& s : names.sequences) {
      std::vector<std::string> row{s};
      for (const std::string& m : names.modes) row.push_back(Cell(runs.Ratios(s, m, s, "plain", metric), 2, "x"));
      table.rows.push_back(row);
    }
    r.tables.push_back(table);
  };
  ratio_to_plain("speed", "Speed ratio to plain (ms/frame of the mode / ms/frame of plain)", ms);
  ratio_to_plain("speed_cpu", "CPU ratio to plain (CPU ms/frame of the mode / CPU ms/frame of plain)", cpu);

  BenchTable detail{
      "timing",
      "Time per frame and per stage [ms] (median over the repeats of each run's mean)",
      "frame: mean / median / p95 of the per-frame time; stages: mean per frame.",
      {"sequence", "mode", "frame mean", "frame median", "frame p95", "detect", "filter",
       "describe", "track", "local map", "mapping"},
      {}};
  BenchTable keypoints{
      "keypoints",
      "Dynamic keypoints: precision / recall [%]",
      "positive = keypoint removed as dynamic; truth = keypoint on a moving-object mask pixel "
      "(synthetic sequences); totals over all frames with masks. 'Moving now': only objects moving "
      "at that frame count (objects.txt); keypoints on an object standing still are left out. "
      "'Outlines': a keypoint whose FAST circle at its pyramid level touches a moving object also "
      "counts as on it (its corner is the object's outline and moves with it).",
      {"sequence", "mode", "precision", "recall", "precision, moving now", "recall, moving now",
       "precision, moving now, outlines", "recall, moving now, outlines", "keypoints on moving objects"},
      {}};
  for (const std::string& s : names.sequences) {
    for (const std::string& m : names.modes) {
      if (!names.Planned(s, m)) continue;
      std::vector<std::string> row{s, m};
      for (const char* stat : {"mean", "median", "p95"})
        row.push_back(Cell(runs.List(s, m, Path({"timing_ms", "frame_total", stat})), 1));
      for (const char* stage :
           {"detect", "filter", "describe", "track", "local_map", "mapping_inline"}) {
        row.push_back(Cell(runs.List(s, m, Path({"timing_ms", stage, "mean"})), 2));
      }
      detail.rows.push_back(row);
      const std::vector<double> precision =
          runs.List(s, m, Path({"dynamic_keypoints", "precision"}, 100.0));
      if (!precision.empty()) {
        keypoints.rows.push_back(
            {s, m, Cell(precision, 1),
             Cell(runs.List(s, m, Path({"dynamic_keypoints", "recall"}, 100.0)), 1),
             Cell(runs.List(s, m, Path({"dynamic_keypoints", "moving_now", "precision"}, 100.0)), 1),
             Cell(runs.List(s, m, Path({"dynamic_keypoints", "moving_now", "recall"}, 100.0)), 1),
             Cell(runs.List(s, m, Path({"dynamic_keypoints", "moving_now", "support", "precision"}, 100.0)), 1),
             Cell(runs.List(s, m, Path({"dynamic_keypoints", "moving_now", "support", "recall"}, 100.0)), 1),
             Cell(runs.List(
                      s, m,
                      Path({"dynamic_keypoints", "keypoints_on_moving_objects_fraction"}, 100.0)),
                  1)});
      }
    }
  }
  r.tables.push_back(detail);
  if (!keypoints.rows.empty()) r.tables.push_back(keypoints);
  // Recall per moving object (the mask's ids present in any run), so that a small mover is seen.
  auto object_recall = [](int id) {
    return Path({"dynamic_keypoints", "moving_now", "by_object", std::to_string(id), "recall"},
                100.0);
  };
  std::set<int> ids;
  for (const Json& run : results["runs"]) {
    const Json* by_object = &run;
    for (const char* key : {"stats", "dynamic_keypoints", "moving_now", "by_object"}) {
      by_object = by_object->is_object() && by_object->contains(key) ? &(*by_object)[key] : nullptr;
      if (by_object == nullptr) break;
    }
    if (by_object == nullptr || run.value("status", "") != "ok") continue;
    for (const auto& [key, counts] : by_object->items()) {
      if (const std::optional<int> id = MaskId(key)) ids.insert(*id);
    }
  }
  if (!ids.empty()) {
    BenchTable objects{"object_recall",
                       "Dynamic keypoints: recall per moving object [%]",
                       "Keypoints on each object of the masks (by id; synthetic sequences: 1-3 "
                       "people, 4 the pushed box, 5 the desk item) at frames where it moves, the "
                       "share removed. '-': not in that sequence.",
                       {"sequence", "mode"},
                       {}};
    for (int id : ids) objects.header.push_back("object " + std::to_string(id));
    for (const std::string& s : names.sequences) {
      for (const std::string& m : names.modes) {
        if (!names.Planned(s, m) || m == "plain") continue;
        std::vector<std::string> row{s, m};
        bool any = false;
        for (int id : ids) {
          const std::vector<double> recall = runs.List(s, m, object_recall(id));
          any = any || !recall.empty();
          row.push_back(Cell(recall, 1));
        }
        if (any) objects.rows.push_back(row);
      }
    }
    if (!objects.rows.empty()) r.tables.push_back(objects);
  }
  if (!names.tum_name.empty()) r.tables.push_back(PublishedTable(runs, names, published));

  for (const std::string& s : names.sequences) {
    for (const std::string& m : names.modes) {
      const std::string key = s + "__" + m;
      if (fs::exists(fs::path(out_dir) / "plots" / (key + ".png"))) {
        r.figures.push_back(
            {"plots/" + key + ".png",
             s + " / " + m +
                 " (first seed): top and side view against ground truth, ATE error over time"});
      }
      if (fs::exists(fs::path(out_dir) / "plots" / (key + "_map.png"))) {
        r.figures.push_back({"plots/" + key + "_map.png",
                             s + " / " + m +
                                 " (first seed): the final map from behind the first keyframe; "
                                 "right: landmarks made on dynamic objects in red"});
      }
      if (fs::exists(fs::path(out_dir) / "plots" / (key + "_keypoints.png"))) {
        r.figures.push_back(
            {"plots/" + key + "_keypoints.png",
             s + " / " + m + ": keypoints kept (green) and removed as dynamic (red)"});
      }
    }
  }
  return r;
}

}  // namespace dynorb
