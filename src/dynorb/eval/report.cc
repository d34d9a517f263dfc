#include "dynorb/eval/report.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "dynorb/core/angles.h"

namespace dynorb {
namespace {

template <typename... Args>
std::string Format(const char* fmt, Args... args) {
  char buf[1024];
  std::snprintf(buf, sizeof(buf), fmt, args...);
  return buf;
}

std::string StatsRow(const char* name, const SummaryStats& s, int precision) {
  return Format("  %-16s %10.*f %10.*f %10.*f %10.*f %10.*f %10.*f %8d\n", name, precision, s.rmse,
                precision, s.mean, precision, s.median, precision, s.stddev, precision, s.min,
                precision, s.max, s.count);
}

nlohmann::json StatsJson(const SummaryStats& s) {
  if (s.count == 0) return nullptr;
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.stddev},
          {"min", s.min},   {"max", s.max},   {"count", s.count}};
}

double AlignmentRotationDeg(const Similarity3d& s) {
  return kDegPerRad * Eigen::AngleAxisd(s.rotation).angle();
}

}  // namespace

const char* const kAteDefinition =
    "TUM evaluate_ate.py: associate.py matching, closed-form Horn/Umeyama alignment, "
    "translational error statistics (std = population)";

std::string RpeDefinition(double delta_s) {
  return Format(
      "TUM evaluate_rpe.py --fixed_delta --delta %g --delta_unit s --max_pairs 0 (all pairs): "
      "E = (est_i^-1 est_j)(gt_i^-1 gt_j)^-1",
      delta_s);
}

std::string FormatReportTable(const EvalResult& r, const ReportInputs& inputs) {
  std::ostringstream out;
  const EvalOptions& o = r.options;
  const Similarity3d& a = r.ate.gt_from_est;
  out << Format("ground truth  %s (%d poses)\n", inputs.groundtruth_label.c_str(), r.gt_poses);
  out << Format("estimate      %s (%d poses)\n", inputs.estimate_label.c_str(), r.est_poses);
  out << Format("association   %d pose pairs (|t_gt - (t_est + %g)| < %g s, one-to-one, greedy)\n",
                r.ate.stats.count, o.association.offset_s, o.association.max_diff_s);
  const std::string gap =
      r.coverage.longest_gap_s > 0.0
          ? Format("longest gap %.2f s, %.2f s after the start", r.coverage.longest_gap_s,
                   r.coverage.longest_gap_start_s - r.coverage.gt_begin_s)
          : std::string("no gap");
  out << Format(
      "coverage      %.1f%% of the %.2f s ground-truth span (+-%g s per matched pose; %s)\n",
      100.0 * r.coverage.fraction, r.coverage.gt_span_s, o.coverage_window_s, gap.c_str());
  out << Format(
      "alignment     %s: scale %.6f, rotation %.3f deg, translation (%.4f, %.4f, %.4f) m\n",
      ToString(r.ate.mode).c_str(), a.scale, AlignmentRotationDeg(a), a.translation.x(),
      a.translation.y(), a.translation.z());
  out << "\n";
  out << Format("  %-16s %10s %10s %10s %10s %10s %10s %8s\n", "", "rmse", "mean", "median", "std",
                "min", "max", "pairs");
  out << StatsRow("ATE [m]", r.ate.stats, 6);
  if (r.rpe.trans_m.count > 0) {
    const std::string unit = o.rpe_delta_s == 1.0 ? "/s" : Format("/%gs", o.rpe_delta_s);
    out << StatsRow(("RPE trans [m" + unit + "]").c_str(), r.rpe.trans_m, 6);
    out << StatsRow(("RPE rot [deg" + unit + "]").c_str(), r.rpe.rot_deg, 6);
  } else {
    out << "  RPE              not available (no pose pair " << o.rpe_delta_s << " s apart)\n";
  }
  out << "\n";
  out << "ATE: " << kAteDefinition << "\n";
  out << "RPE: " << RpeDefinition(o.rpe_delta_s);
  if (r.ate.mode == AlignmentMode::kSim3)
    out << Format("; est translations x %.6f (sim3 scale)", a.scale);
  out << "\n";
  for (const std::string& w : r.warnings) out << "warning: " << w << "\n";
  return out.str();
}

std::string FormatReportJson(const EvalResult& r, const ReportInputs& inputs) {
  using nlohmann::json;
  const EvalOptions& o = r.options;
  const Similarity3d& a = r.ate.gt_from_est;
  json rotation = json::array();
  for (int row = 0; row < 3; ++row)
    rotation.push_back({a.rotation(row, 0), a.rotation(row, 1), a.rotation(row, 2)});
  json j;
  j["schema"] = "dynorb.eval/1";
  j["inputs"] = {{"groundtruth", inputs.groundtruth_label},
                 {"estimate", inputs.estimate_label},
                 {"groundtruth_poses", r.gt_poses},
                 {"estimate_poses", r.est_poses}};
  j["options"] = {{"align", ToString(o.alignment)},
                  {"max_diff_s", o.association.max_diff_s},
                  {"offset_s", o.association.offset_s},
                  {"rpe_delta_s", o.rpe_delta_s},
                  {"coverage_window_s", o.coverage_window_s}};
  j["association"] = {{"pairs", r.ate.stats.count},
                      {"unmatched_estimate_poses", r.est_poses - r.ate.stats.count}};
  j["coverage"] = {
      {"fraction", r.coverage.fraction},
      {"groundtruth_span_s", r.coverage.gt_span_s},
      {"covered_s", r.coverage.covered_s},
      {"longest_gap_s", r.coverage.longest_gap_s},
      {"longest_gap_start_s", r.coverage.longest_gap_start_s},
      {"definition", Format("fraction of the ground-truth time span within +-%g s of an "
                            "associated estimate pose",
                            o.coverage_window_s)}};
  j["alignment"] = {{"mode", ToString(r.ate.mode)},
                    {"scale", a.scale},
                    {"rotation", rotation},
                    {"rotation_angle_deg", AlignmentRotationDeg(a)},
                    {"translation_m", {a.translation.x(), a.translation.y(), a.translation.z()}}};
  j["ate_m"] = StatsJson(r.ate.stats);
  j["ate_m"]["definition"] = kAteDefinition;
  j["rpe"] = {{"definition", RpeDefinition(o.rpe_delta_s)},
              {"delta_s", o.rpe_delta_s},
              {"scale_applied", a.scale},
              {"pairs", r.rpe.trans_m.count},
              {"gt_max_time_difference_s", r.rpe.gt_max_time_difference_s},
              {"trans_m", StatsJson(r.rpe.trans_m)},
              {"rot_deg", StatsJson(r.rpe.rot_deg)},
              {"trans_paper_form_m", StatsJson(r.rpe.trans_paper_form_m)}};
  j["warnings"] = r.warnings;
  // A label (a file path) need not be UTF-8: invalid bytes become U+FFFD instead of throwing.
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace dynorb
