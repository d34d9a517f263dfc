#include "dynorb/core/stats.h"

#include <algorithm>
#include <cmath>

namespace dynorb {
namespace {
double Percentile(const std::vector<double>& sorted, double q) {
  const double pos = q * (static_cast<double>(sorted.size()) - 1.0);
  const auto lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, sorted.size() - 1);
  const double frac = pos - static_cast<double>(lo);
  return sorted[lo] + frac * (sorted[hi] - sorted[lo]);
}
}  // namespace

SummaryStats Summarize(std::vector<double> values) {
  SummaryStats s;
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  s.count = static_cast<int>(values.size());
  double sum = 0.0, sum_sq = 0.0;
  for (double v : values) {
    sum += v;
    sum_sq += v * v;
  }
  const double n = static_cast<double>(values.size());
  s.mean = sum / n;
  double var = 0.0;
  for (double v : values) var += (v - s.mean) * (v - s.mean);
  s.stddev = std::sqrt(var / n);
  s.rmse = std::sqrt(sum_sq / n);
  s.min = values.front();
  s.max = values.back();
  s.median = Percentile(values, 0.5);
  s.p95 = Percentile(values, 0.95);
  return s;
}

}  // namespace dynorb
