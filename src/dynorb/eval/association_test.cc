#include "dynorb/eval/association.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

// associate.py's rule written literally: all candidates, sort, greedy. O(n m), for checking.
std::vector<IndexPair> BruteForce(const std::vector<double>& gt, const std::vector<double>& est,
                                  double max_diff, double offset) {
  std::vector<std::tuple<double, double, double, int, int>> candidates;
  for (size_t a = 0; a < gt.size(); ++a) {
    for (size_t b = 0; b < est.size(); ++b) {
      const double diff = std::abs(gt[a] - (est[b] + offset));
      if (diff < max_diff) candidates.emplace_back(diff, gt[a], est[b], int(a), int(b));
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<bool> gt_used(gt.size()), est_used(est.size());
  std::vector<IndexPair> pairs;
  for (const auto& [diff, ta, tb, a, b] : candidates) {
    if (gt_used[a] || est_used[b]) continue;
    gt_used[a] = est_used[b] = true;
    pairs.push_back({a, b});
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const IndexPair& x, const IndexPair& y) { return x.gt < y.gt; });
  return pairs;
}

StampAssociationOptions Options(double max_diff, double offset = 0.0) {
  StampAssociationOptions o;
  o.max_diff_s = max_diff;
  o.offset_s = offset;
  return o;
}

TEST(Association, ClosestWinsConflict) {
  // Both estimates want gt 0; the closer one (0.005) gets it, the other stays unmatched.
  const auto pairs = AssociateStamps({0.0, 1.0}, {-0.01, 0.005}, Options(0.02));
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], (IndexPair{0, 1}));
}

TEST(Association, GreedyIsNotOptimalAndMayCross) {
  // Smallest difference first: (gt 0.012, est 0.007) = 0.005; then (gt 0.000, est 0.019) =
  // 0.019 < 0.02 is still accepted: the greedy rule of associate.py, crossing pairs included.
  const auto pairs = AssociateStamps({0.000, 0.012}, {0.007, 0.019}, Options(0.02));
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0], (IndexPair{0, 1}));
  EXPECT_EQ(pairs[1], (IndexPair{1, 0}));
}

TEST(Association, ThresholdIsStrict) {
  EXPECT_TRUE(AssociateStamps({0.0}, {0.5}, Options(0.5)).empty());
  EXPECT_EQ(AssociateStamps({0.0}, {0.25}, Options(0.5)).size(), 1u);
}

TEST(Association, OffsetIsAddedToEstimate) {
  // est + offset = gt exactly.
  const auto pairs = AssociateStamps({10.0, 10.5, 11.0}, {9.0, 9.5, 10.0}, Options(0.02, 1.0));
  ASSERT_EQ(pairs.size(), 3u);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(pairs[k], (IndexPair{k, k}));
  EXPECT_TRUE(AssociateStamps({10.0, 10.5, 11.0}, {9.0, 9.5, 10.0}, Options(0.02)).size() == 1u);
}

TEST(Association, TieBrokenByGroundTruthStampThenEstimateStamp) {
  // est 0.5 is 0.25 from both gt 0.25 and gt 0.75: associate.py's tuple sort prefers gt 0.25.
  const auto pairs = AssociateStamps({0.25, 0.75}, {0.5}, Options(0.3));
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], (IndexPair{0, 0}));
}

TEST(Association, MatchesBruteForceOnRandomConflicts) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 300; ++trial) {
    std::uniform_real_distribution<double> step(0.001, trial % 3 == 0 ? 0.01 : 0.05);
    std::vector<double> gt, est;
    double t = 0.0;
    for (int k = 0; k < 60; ++k) gt.push_back(t += step(rng));
    t = 0.0;
    for (int k = 0; k < 45; ++k) est.push_back(t += step(rng));
    const double max_diff = std::uniform_real_distribution<double>(0.001, 0.2)(rng);
    const double offset =
        trial % 2 ? std::uniform_real_distribution<double>(-0.05, 0.05)(rng) : 0.0;
    EXPECT_EQ(AssociateStamps(gt, est, Options(max_diff, offset)),
              BruteForce(gt, est, max_diff, offset))
        << "trial " << trial;
  }
}

TEST(Association, MatchesBruteForceWithEqualStampsAndTies) {
  // Quantised stamps create many exact ties.
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> gt, est;
    for (int k = 0; k < 40; ++k) {
      if (rng() % 3) gt.push_back(k * 0.125);
      if (rng() % 2) est.push_back(k * 0.125);
    }
    const double max_diff = 0.125 * (1 + rng() % 4);
    EXPECT_EQ(AssociateStamps(gt, est, Options(max_diff)), BruteForce(gt, est, max_diff, 0.0))
        << trial;
  }
}

TEST(Association, RejectsBadInput) {
  EXPECT_THROW(AssociateStamps({0.0, 0.0}, {0.0}, Options(0.02)), InputError);
  EXPECT_THROW(AssociateStamps({0.0}, {1.0, 0.5}, Options(0.02)), InputError);
  EXPECT_THROW(AssociateStamps({0.0}, {0.0}, Options(0.0)), InputError);
  EXPECT_THROW(AssociateStamps({0.0}, {0.0}, Options(NAN)), InputError);
  EXPECT_TRUE(AssociateStamps({}, {0.0}, Options(0.02)).empty());
}

}  // namespace
}  // namespace dynorb
