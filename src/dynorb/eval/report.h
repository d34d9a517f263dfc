// Text and JSON reports of an EvalResult (the stdout table and the --json file of `dynorb eval`).
// Pure functions, thread-safe. The JSON schema is documented in docs/evaluation.md.
#pragma once

#include <string>

#include "dynorb/eval/evaluate.h"

namespace dynorb {

struct ReportInputs {
  std::string groundtruth_label;  // e.g. the ground-truth file path
  std::string estimate_label;
};

// Aligned, human-readable table; ends with "warning: ..." lines if any.
std::string FormatReportTable(const EvalResult& result, const ReportInputs& inputs);

// Pretty-printed JSON (schema version 1), ending with a newline.
std::string FormatReportJson(const EvalResult& result, const ReportInputs& inputs);

// One-line descriptions of the definitions, shared by the table, JSON and plot title.
extern const char* const kAteDefinition;
std::string RpeDefinition(double delta_s);

}  // namespace dynorb
