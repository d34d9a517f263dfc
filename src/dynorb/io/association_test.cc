#include "dynorb/io/association.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

using Pairs = std::vector<std::pair<size_t, size_t>>;

// Literal transcription of the rule of TUM's associate.py (O(n*m)), as the reference.
Pairs ReferenceAssociate(const std::vector<double>& first, const std::vector<double>& second,
                         double offset, double max_difference) {
  std::vector<std::tuple<double, double, double, size_t, size_t>> potential;
  for (size_t i = 0; i < first.size(); ++i) {
    for (size_t j = 0; j < second.size(); ++j) {
      const double d = std::abs(first[i] - (second[j] + offset));
      if (d < max_difference) potential.emplace_back(d, first[i], second[j], i, j);
    }
  }
  std::sort(potential.begin(), potential.end());
  std::vector<bool> used_a(first.size()), used_b(second.size());
  std::vector<std::tuple<double, double, size_t, size_t>> matches;
  for (const auto& [d, a, b, i, j] : potential) {
    if (used_a[i] || used_b[j]) continue;
    used_a[i] = used_b[j] = true;
    matches.emplace_back(a, b, i, j);
  }
  std::sort(matches.begin(), matches.end());
  Pairs out;
  for (const auto& m : matches) out.emplace_back(std::get<2>(m), std::get<3>(m));
  return out;
}

// Stamps below are exact binary fractions, so every difference is computed exactly.
TEST(AssociateTimestamps, NearestWithinWindow) {
  const Pairs p = AssociateTimestamps({1.0, 2.0, 3.0}, {1.0078125, 2.0625, 2.9921875}, {0.02, 0.0});
  EXPECT_EQ(p, (Pairs{{0, 0}, {2, 2}}));  // 2.0 vs 2.0625 is outside the window
}

TEST(AssociateTimestamps, WindowIsStrict) {
  EXPECT_TRUE(AssociateTimestamps({10.0}, {10.5}, {0.5, 0.0}).empty());
  EXPECT_EQ(AssociateTimestamps({10.0}, {10.25}, {0.5, 0.0}), (Pairs{{0, 0}}));
}

TEST(AssociateTimestamps, GreedyConflictTakesSmallestDifferenceFirst) {
  // Candidates: (a1,b0)=.125 (a1,b1)=.125 (a0,b0)=.25; (a0,b1)=.5 is not < .5.
  // Greedy accepts (a1,b0) (tie broken by the smaller second stamp), then a1 and b0 are used:
  // a0 and b1 stay unmatched although the matching {(a0,b0),(a1,b1)} exists.
  const Pairs p = AssociateTimestamps({10.0, 10.375}, {10.25, 10.5}, {0.5, 0.0});
  EXPECT_EQ(p, (Pairs{{1, 0}}));
  // Equal differences: ties broken by the first stamp, then the second.
  EXPECT_EQ(AssociateTimestamps({10.0, 10.5}, {10.25, 10.75}, {0.5, 0.0}), (Pairs{{0, 0}, {1, 1}}));
  // One depth stamp wanted by two rgb stamps: the closer rgb stamp wins.
  EXPECT_EQ(AssociateTimestamps({10.0, 10.375}, {10.25}, {0.5, 0.0}), (Pairs{{1, 0}}));
}

TEST(AssociateTimestamps, OffsetIsAddedToSecondStamps) {
  EXPECT_TRUE(AssociateTimestamps({10.0}, {9.75}, {0.125, 0.0}).empty());
  EXPECT_EQ(AssociateTimestamps({10.0}, {9.75}, {0.125, 0.25}), (Pairs{{0, 0}}));
  EXPECT_EQ(AssociateTimestamps({10.0}, {9.75, 10.125}, {0.5, 0.0}), (Pairs{{0, 1}}));
  EXPECT_EQ(AssociateTimestamps({10.0}, {9.75, 10.125}, {0.5, 0.25}), (Pairs{{0, 0}}));
}

TEST(AssociateTimestamps, ResultSortedByFirstStampForUnsortedInput) {
  const Pairs p = AssociateTimestamps({3.0, 1.0, 2.0}, {2.0078125, 0.9921875, 3.0}, {0.02, 0.0});
  EXPECT_EQ(p, (Pairs{{1, 1}, {2, 0}, {0, 2}}));
}

TEST(AssociateTimestamps, MatchesReferenceOnRandomStreams) {
  std::mt19937 rng(42);
  for (int trial = 0; trial < 20; ++trial) {
    std::uniform_real_distribution<double> jitter(-0.015, 0.015);
    std::uniform_real_distribution<double> period(0.02, 0.04);
    std::bernoulli_distribution drop(0.1);
    std::vector<double> a, b;
    double t = 1341846313.0 + trial;
    for (int k = 0; k < 400; ++k) {
      t += period(rng);
      if (!drop(rng)) a.push_back(t);
      if (!drop(rng)) b.push_back(t + jitter(rng));
    }
    if (trial % 2 == 1) std::shuffle(b.begin(), b.end(), rng);
    const double max_diff = trial % 3 == 0 ? 0.02 : 0.035;
    const double offset = trial % 4 == 0 ? 0.0 : jitter(rng);
    const Pairs expected = ReferenceAssociate(a, b, offset, max_diff);
    EXPECT_EQ(AssociateTimestamps(a, b, {max_diff, offset}), expected) << "trial " << trial;
    EXPECT_GT(expected.size(), 100u);
  }
}

TEST(AssociateTimestamps, ThirtyMinuteSequence) {
  // 30 min at 30 Hz: 54000 stamps each, depth 0.5 ms after rgb; must be fast (windowed).
  std::vector<double> rgb, depth;
  for (int k = 0; k < 54000; ++k) {
    rgb.push_back(1e9 + k / 30.0);
    depth.push_back(1e9 + k / 30.0 + 0.0005);
  }
  const Pairs p = AssociateTimestamps(rgb, depth);
  ASSERT_EQ(p.size(), 54000u);
  for (size_t k = 0; k < p.size(); ++k) ASSERT_EQ(p[k], std::make_pair(k, k));
}

TEST(AssociationOptions, Validate) {
  EXPECT_THROW((AssociationOptions{0.0, 0.0}.Validate()), InputError);
  EXPECT_THROW((AssociationOptions{-1.0, 0.0}.Validate()), InputError);
  EXPECT_THROW((AssociationOptions{0.02, NAN}.Validate()), InputError);
  EXPECT_NO_THROW((AssociationOptions{0.02, -0.1}.Validate()));
}

TEST(AssociateImageLists, NoAssociationsIsAnError) {
  try {
    AssociateImageLists({{1.0, "rgb/1.png"}}, {{2.0, "depth/2.png"}});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no rgb/depth associations found"), std::string::npos);
  }
}

}  // namespace
}  // namespace dynorb
