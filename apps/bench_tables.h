// The tables of a `dynorb bench` report, computed from results.json (bench_runner.h) and the
// published numbers (bench/published_results.json), independent of the output format
// (bench_report.h renders them as Markdown and HTML). Pure functions.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace dynorb {

struct BenchTable {
  std::string id;     // anchor, e.g. "ate"
  std::string title;  // e.g. "ATE RMSE [m]"
  std::string note;   // one paragraph under the title (plain text)
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

// A figure of the report: an image below OUT/ and its caption.
struct BenchFigure {
  std::string path;  // relative to OUT, e.g. plots/seq__plain.png
  std::string caption;
};

struct BenchReportContent {
  std::string title;
  std::vector<std::string> summary;  // lines: suite, date, seeds, runs, failures
  std::vector<BenchTable> tables;
  std::vector<BenchFigure> figures;
};

// `out_dir` is only used to check which plot files exist. Throws InputError when `results` is
// not a dynorb bench result.
BenchReportContent BuildBenchReport(const nlohmann::json& results, const nlohmann::json& published,
                                    const std::string& out_dir);

}  // namespace dynorb
