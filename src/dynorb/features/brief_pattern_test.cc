#include "dynorb/features/brief_pattern.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <set>
#include <tuple>

namespace dynorb {
namespace {

uint64_t Fnv1a(const std::array<BriefPair, kBriefBits>& pattern) {
  uint64_t h = 1469598103934665603ULL;
  for (const BriefPair& p : pattern) {
    for (int8_t v : {p.x1, p.y1, p.x2, p.y2}) {
      h ^= static_cast<uint8_t>(v);
      h *= 1099511628211ULL;
    }
  }
  return h;
}

TEST(BriefPattern, PointsInsideDiscPairsDistinctAndUnique) {
  const auto& pattern = BriefPattern();
  std::set<std::tuple<int, int, int, int>> seen;
  for (const BriefPair& p : pattern) {
    EXPECT_LE(p.x1 * p.x1 + p.y1 * p.y1, kBriefMaxRadius * kBriefMaxRadius);
    EXPECT_LE(p.x2 * p.x2 + p.y2 * p.y2, kBriefMaxRadius * kBriefMaxRadius);
    EXPECT_FALSE(p.x1 == p.x2 && p.y1 == p.y2);
    EXPECT_EQ(seen.count({p.x2, p.y2, p.x1, p.y1}), 0u);
    EXPECT_TRUE(seen.insert({p.x1, p.y1, p.x2, p.y2}).second);
  }
}

TEST(BriefPattern, LearnedFromTheDocumentedCandidatePool) {
  const std::vector<BriefPair> candidates = GenerateBriefCandidates(kBriefCandidateSeed, 16384);
  std::set<std::tuple<int, int, int, int>> pool;
  for (const BriefPair& p : candidates) pool.insert({p.x1, p.y1, p.x2, p.y2});
  for (const BriefPair& p : BriefPattern()) EXPECT_EQ(pool.count({p.x1, p.y1, p.x2, p.y2}), 1u);
}

TEST(BriefPattern, Pinned) {
  // A change here changes every descriptor and invalidates trained vocabularies.
  EXPECT_EQ(Fnv1a(BriefPattern()), 8421394333484012446ULL);
}

}  // namespace
}  // namespace dynorb
