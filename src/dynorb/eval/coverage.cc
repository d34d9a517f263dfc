#include "dynorb/eval/coverage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "dynorb/core/error.h"
#include "dynorb/eval/text_format.h"

namespace dynorb {

void CoverageOptions::Validate() const {
  if (!(window_s > 0.0) || !std::isfinite(window_s)) {
    throw InputError("coverage window must be a positive number of seconds, got " +
                     ShortNumber(window_s));
  }
  if (!std::isfinite(offset_s)) throw InputError("--offset must be finite");
}

Coverage ComputeCoverage(const Trajectory& gt, const Trajectory& est,
                         const std::vector<IndexPair>& pairs, const CoverageOptions& options) {
  options.Validate();
  Coverage c;
  if (gt.empty()) return c;
  const double begin = gt.front().timestamp_s;
  const double end = gt.back().timestamp_s;
  c.gt_begin_s = begin;
  c.gt_span_s = end - begin;
  std::vector<double> centers;
  centers.reserve(pairs.size());
  for (const IndexPair& p : pairs) centers.push_back(est[p.est].timestamp_s + options.offset_s);
  std::sort(centers.begin(), centers.end());

  // Sweep: `reached` is the end of the covered prefix; every jump past it is a gap.
  double reached = begin;
  auto note_gap = [&](double from, double to) {
    if (to - from > c.longest_gap_s) {
      c.longest_gap_s = to - from;
      c.longest_gap_start_s = from;
    }
  };
  for (double s : centers) {
    const double lo = std::clamp(s - options.window_s, begin, end);
    const double hi = std::clamp(s + options.window_s, begin, end);
    if (lo > reached) note_gap(reached, lo);
    if (hi > std::max(lo, reached)) c.covered_s += hi - std::max(lo, reached);
    reached = std::max(reached, hi);
  }
  if (end > reached) note_gap(reached, end);
  c.fraction = c.gt_span_s > 0.0 ? c.covered_s / c.gt_span_s : (pairs.empty() ? 0.0 : 1.0);
  return c;
}

}  // namespace dynorb
