// Summary statistics of a sample (timings, errors). Pure functions, thread-safe.
#pragma once

#include <vector>

namespace dynorb {

struct SummaryStats {
  int count = 0;
  double mean = 0.0, median = 0.0, stddev = 0.0, min = 0.0, max = 0.0, rmse = 0.0, p95 = 0.0;
};

// stddev is the population standard deviation (numpy's default, as in TUM's evaluate_ate.py).
// p95 uses linear interpolation between order statistics (numpy.percentile's default).
SummaryStats Summarize(std::vector<double> values);

}  // namespace dynorb
