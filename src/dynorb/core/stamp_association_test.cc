#include "dynorb/core/stamp_association.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>

namespace dynorb {
namespace {

// associate.py, literally: every candidate, sorted, greedy; then sorted by the first stamp.
std::vector<std::pair<size_t, size_t>> BruteForce(const std::vector<double>& a,
                                                  const std::vector<double>& b, double max_diff,
                                                  double offset) {
  std::vector<std::tuple<double, double, double, size_t, size_t>> candidates;
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t j = 0; j < b.size(); ++j) {
      const double d = std::abs(a[i] - (b[j] + offset));
      if (d < max_diff) candidates.emplace_back(d, a[i], b[j], i, j);
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<bool> used_a(a.size()), used_b(b.size());
  std::vector<std::pair<size_t, size_t>> out;
  for (const auto& [d, ta, tb, i, j] : candidates) {
    if (used_a[i] || used_b[j]) continue;
    used_a[i] = used_b[j] = true;
    out.emplace_back(i, j);
  }
  std::sort(out.begin(), out.end(),
            [&](const auto& x, const auto& y) { return a[x.first] < a[y.first]; });
  return out;
}

TEST(AssociateNearestStamps, EqualsAssociatePyOnUnsortedListsAndWideWindows) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> stamp(0.0, 3.0);
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<double> a(30 + trial), b(25 + 2 * trial);
    for (double& t : a) t = std::round(stamp(rng) * 1000.0) / 1000.0;  // ms grid: many ties
    for (double& t : b) t = std::round(stamp(rng) * 1000.0) / 1000.0;
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    std::sort(b.begin(), b.end());
    b.erase(std::unique(b.begin(), b.end()), b.end());
    std::shuffle(a.begin(), a.end(), rng);  // The lists need not be sorted.
    std::shuffle(b.begin(), b.end(), rng);
    for (const double max_diff : {0.02, 0.3, 10.0}) {
      const double offset = trial % 3 == 0 ? 0.0 : 0.011 * (trial % 5);
      SCOPED_TRACE(testing::Message() << "trial " << trial << " max_diff " << max_diff);
      EXPECT_EQ(AssociateNearestStamps(a, b, max_diff, offset), BruteForce(a, b, max_diff, offset));
    }
  }
  EXPECT_TRUE(AssociateNearestStamps({}, {1.0}, 0.02, 0.0).empty());
}

}  // namespace
}  // namespace dynorb
