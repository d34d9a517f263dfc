#include "dynorb/map/match_rules.h"

#include <algorithm>
#include <cmath>

namespace dynorb {

constexpr int kHistogramBins = 30;

std::vector<bool> OrientationConsistent(const std::vector<float>& angle_deltas_deg) {
  std::vector<int> bins(angle_deltas_deg.size());
  std::vector<int> counts(kHistogramBins, 0);
  for (size_t i = 0; i < angle_deltas_deg.size(); ++i) {
    int bin = static_cast<int>(std::lround(angle_deltas_deg[i] * kHistogramBins / 360.0f));
    if (bin == kHistogramBins) bin = 0;
    bins[i] = bin;
    ++counts[bin];
  }
  // Three dominant bins; the 2nd and 3rd only if they hold at least 10 % of the first.
  std::vector<int> order(kHistogramBins);
  for (int i = 0; i < kHistogramBins; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return counts[a] > counts[b]; });
  std::vector<bool> keep_bin(kHistogramBins, false);
  keep_bin[order[0]] = true;
  for (int k = 1; k < 3; ++k) {
    if (counts[order[k]] > 0.1 * counts[order[0]]) keep_bin[order[k]] = true;
  }
  std::vector<bool> keep(angle_deltas_deg.size());
  for (size_t i = 0; i < keep.size(); ++i) keep[i] = keep_bin[bins[i]];
  return keep;
}

int PredictLevel(double max_distance_m, double distance_m, const ScaleLevels& levels) {
  if (distance_m <= 0.0 || max_distance_m <= 0.0) return 0;
  const int level = static_cast<int>(std::ceil(std::log(max_distance_m / distance_m) / levels.log_scale_factor));
  return std::clamp(level, 0, levels.NumLevels() - 1);
}

}  // namespace dynorb
