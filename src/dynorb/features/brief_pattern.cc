#include "dynorb/features/brief_pattern.h"

#include <cmath>
#include <set>
#include <tuple>

namespace dynorb {
namespace {

// SplitMix64 (Steele, Lea, Flood 2014): a tiny, well-mixed, portable 64-bit generator.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }

 private:
  uint64_t state_;
};

// Approximately N(0, sigma²), rounded to the nearest integer: the sum of 12 U(0,1) has mean 6 and
// variance 1. The sum is exact in integers; only the final scaling is floating point.
int SampleGaussianPixel(SplitMix64& rng, double sigma) {
  uint64_t sum = 0;
  for (int i = 0; i < 12; ++i) sum += rng.Next() >> 32;  // 12 × 32-bit uniforms, no overflow
  const double unit = static_cast<double>(static_cast<int64_t>(sum) - (int64_t{6} << 32)) /
                      4294967296.0;  // exact: division by 2^32
  return static_cast<int>(std::lround(unit * sigma));
}

int SampleUniformPixel(SplitMix64& rng, int max_radius) {
  return static_cast<int>((rng.Next() >> 32) % (2 * max_radius + 1)) - max_radius;
}

// Learned by brief_learning.h from GenerateBriefCandidates(kBriefCandidateSeed, 16384) on the
// training images of docs/features.md. Regenerate with the DISABLED_ test of
// brief_learning_test.cc.
constexpr BriefPair kLearnedPattern[kBriefBits] = {
#include "dynorb/features/brief_pattern_table.inc"
};

}  // namespace

std::vector<BriefPair> GenerateBriefCandidates(uint64_t seed, int count, int max_radius) {
  const double sigma = 31.0 / 5.0;  // BRIEF "G II": sigma² = S² / 25 for the patch size S = 31
  SplitMix64 rng(seed);
  auto sample_point = [&](bool gaussian, int* x, int* y) {
    do {
      *x = gaussian ? SampleGaussianPixel(rng, sigma) : SampleUniformPixel(rng, max_radius);
      *y = gaussian ? SampleGaussianPixel(rng, sigma) : SampleUniformPixel(rng, max_radius);
    } while (*x * *x + *y * *y > max_radius * max_radius);
  };
  std::vector<BriefPair> pairs;
  pairs.reserve(count);
  std::set<std::tuple<int, int, int, int>> used;
  while (static_cast<int>(pairs.size()) < count) {
    const bool gaussian = pairs.size() % 2 == 0;
    int x1, y1, x2, y2;
    sample_point(gaussian, &x1, &y1);
    sample_point(gaussian, &x2, &y2);
    if (x1 == x2 && y1 == y2) continue;
    // A pair and its swap test the same thing (complemented bit): reject both repeats.
    if (used.count({x1, y1, x2, y2}) || used.count({x2, y2, x1, y1})) continue;
    used.insert({x1, y1, x2, y2});
    pairs.push_back(BriefPair{static_cast<int8_t>(x1), static_cast<int8_t>(y1),
                              static_cast<int8_t>(x2), static_cast<int8_t>(y2)});
  }
  return pairs;
}

const std::array<BriefPair, kBriefBits>& BriefPattern() {
  static const std::array<BriefPair, kBriefBits> kPattern = [] {
    std::array<BriefPair, kBriefBits> p{};
    for (int i = 0; i < kBriefBits; ++i) p[i] = kLearnedPattern[i];
    return p;
  }();
  return kPattern;
}

}  // namespace dynorb
