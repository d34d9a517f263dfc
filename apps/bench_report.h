// Reports of `dynorb bench`: report.md and report.html from results.json (bench_runner.h), so a
// stored results.json can be re-reported without running anything (`dynorb bench --report DIR`).
//
// Tables (median over the repeats, [min-max] when there are several): ATE RMSE, RPE, tracked
// fraction, lost episodes, ms/frame, the robustness ratio ATE(dynamic)/ATE(static twin) (paired
// by seed), the speed ratio to `plain` (paired by seed), per-stage times, dynamic-keypoint
// precision/recall (sequences with masks), and for real TUM sequences the published numbers of
// other systems (bench/published_results.json, one source per row). Figures are linked from
// OUT/plots/ when present. Pure function of its inputs; thread-compatible.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace dynorb {

// `published` may be null (no published table). Writes out_dir/report.md and out_dir/report.html
// atomically; throws InputError for a results.json that is not a dynorb bench result.
void WriteBenchReport(const nlohmann::json& results, const nlohmann::json& published,
                      const std::string& out_dir);

// Reads a JSON file; throws InputError naming the file when it is missing or malformed.
nlohmann::json ReadBenchJson(const std::string& path);

}  // namespace dynorb
