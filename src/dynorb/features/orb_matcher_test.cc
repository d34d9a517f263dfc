#include "dynorb/features/orb_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

cv::Mat RandomDescriptors(int n, uint64_t seed) {
  cv::Mat d(n, kBriefBytes, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(d, cv::RNG::UNIFORM, 0, 256);
  return d;
}

int NaiveDistance(const uint8_t* a, const uint8_t* b) {
  int d = 0;
  for (int i = 0; i < kBriefBits; ++i)
    d += ((a[i / 8] >> (i % 8)) & 1) != ((b[i / 8] >> (i % 8)) & 1);
  return d;
}

TEST(Popcount64, EdgeWordsAndRandomWordsMatchBitLoop) {
  EXPECT_EQ(Popcount64(0), 0);
  EXPECT_EQ(Popcount64(~0ULL), 64);
  EXPECT_EQ(Popcount64(1ULL << 63), 1);
  EXPECT_EQ(Popcount64(0x8000000000000001ULL), 2);
  std::mt19937_64 rng(3);
  for (int k = 0; k < 1000; ++k) {
    const uint64_t x = rng();
    int bits = 0;
    for (int b = 0; b < 64; ++b) bits += static_cast<int>((x >> b) & 1ULL);
    EXPECT_EQ(Popcount64(x), bits) << std::hex << x;
  }
}

TEST(HammingDistance256, MatchesNaiveBitCount) {
  const cv::Mat a = RandomDescriptors(200, 1), b = RandomDescriptors(200, 2);
  for (int i = 0; i < 200; ++i) {
    for (int j = 0; j < 200; j += 7) {
      EXPECT_EQ(HammingDistance256(a, i, b, j), NaiveDistance(a.ptr(i), b.ptr(j)));
    }
    EXPECT_EQ(HammingDistance256(a, i, a, i), 0);
  }
  cv::Mat zeros(1, kBriefBytes, CV_8UC1, cv::Scalar(0)),
      ones(1, kBriefBytes, CV_8UC1, cv::Scalar(255));
  EXPECT_EQ(HammingDistance256(zeros, 0, ones, 0), 256);
  // Unaligned rows (a column range view) work too.
  cv::Mat wide = RandomDescriptors(3, 3);
  cv::Mat big(3, kBriefBytes + 1, CV_8UC1);
  wide.copyTo(big.colRange(1, kBriefBytes + 1));
  EXPECT_EQ(HammingDistance256(big.ptr(0) + 1, wide.ptr(1)),
            NaiveDistance(wide.ptr(0), wide.ptr(1)));
}

// Reference implementation of MatchBruteForce's documented semantics.
std::vector<DescriptorMatch> NaiveMatch(const cv::Mat& q, const cv::Mat& t,
                                        const BruteForceMatchOptions& o) {
  auto best_of = [](const cv::Mat& from, int row, const cv::Mat& to, int* best, int* best_d,
                    int* second_d) {
    *best = -1;
    *best_d = *second_d = std::numeric_limits<int>::max();
    for (int j = 0; j < to.rows; ++j) {
      const int d = NaiveDistance(from.ptr(row), to.ptr(j));
      if (d < *best_d) {
        *second_d = *best_d;
        *best_d = d;
        *best = j;
      } else if (d < *second_d) {
        *second_d = d;
      }
    }
  };
  std::vector<DescriptorMatch> out;
  for (int i = 0; i < q.rows; ++i) {
    int best, best_d, second_d;
    best_of(q, i, t, &best, &best_d, &second_d);
    if (best_d > o.max_distance) continue;
    if (o.max_ratio < 1.0 && second_d != std::numeric_limits<int>::max() &&
        !(best_d < o.max_ratio * second_d))
      continue;
    if (o.mutual_check) {
      int back, back_d, unused;
      best_of(t, best, q, &back, &back_d, &unused);
      if (back != i) continue;
    }
    out.push_back({i, best, best_d});
  }
  return out;
}

cv::Mat Perturb(const cv::Mat& d, int flips, uint64_t seed) {
  cv::Mat out = d.clone();
  std::mt19937 rng(static_cast<uint32_t>(seed));
  for (int r = 0; r < out.rows; ++r) {
    for (int f = 0; f < flips; ++f) {
      const int bit = static_cast<int>(rng() % kBriefBits);
      out.at<uint8_t>(r, bit / 8) ^= static_cast<uint8_t>(1u << (bit % 8));
    }
  }
  return out;
}

TEST(MatchBruteForce, RecoversPerturbedPermutation) {
  const cv::Mat train = RandomDescriptors(300, 4);
  std::vector<int> perm(300);
  for (int i = 0; i < 300; ++i) perm[i] = (i * 97) % 300;
  cv::Mat query(300, kBriefBytes, CV_8UC1);
  for (int i = 0; i < 300; ++i) train.row(perm[i]).copyTo(query.row(i));
  query = Perturb(query, 20, 5);
  const std::vector<DescriptorMatch> m = MatchBruteForce(query, train);
  ASSERT_EQ(m.size(), 300u);
  for (int i = 0; i < 300; ++i) {
    EXPECT_EQ(m[i].query_index, i);
    EXPECT_EQ(m[i].train_index, perm[i]);
    EXPECT_LE(m[i].distance, 20);
  }
}

TEST(MatchBruteForce, AgreesWithNaiveReference) {
  const cv::Mat base = RandomDescriptors(120, 6);
  const cv::Mat query = Perturb(base, 45, 7);
  cv::Mat train;
  cv::vconcat(Perturb(base.rowRange(0, 80), 50, 8), RandomDescriptors(60, 9), train);
  for (const BruteForceMatchOptions& o :
       {BruteForceMatchOptions{}, BruteForceMatchOptions{256, 1.0, false},
        BruteForceMatchOptions{70, 0.9, true}, BruteForceMatchOptions{100, 0.6, false}}) {
    const std::vector<DescriptorMatch> got = MatchBruteForce(query, train, o);
    const std::vector<DescriptorMatch> want = NaiveMatch(query, train, o);
    ASSERT_EQ(got.size(), want.size());
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].query_index, want[i].query_index);
      EXPECT_EQ(got[i].train_index, want[i].train_index);
      EXPECT_EQ(got[i].distance, want[i].distance);
    }
  }
}

TEST(MatchBruteForce, RatioAndMutualChecksReject) {
  const cv::Mat a = RandomDescriptors(2, 10);
  cv::Mat train;
  cv::vconcat(a.row(0), a.row(0), train);  // two identical candidates: ambiguous
  EXPECT_TRUE(MatchBruteForce(a.row(0), train).empty());
  EXPECT_EQ(MatchBruteForce(a.row(0), train, {100, 1.0, true}).size(), 1u);
  // Two queries want the same train row: the mutual check keeps only the closer one.
  cv::Mat query;
  cv::vconcat(Perturb(a.row(1), 5, 11), Perturb(a.row(1), 10, 12), query);
  const auto m = MatchBruteForce(query, a.row(1), {100, 1.0, true});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].query_index, 0);
  EXPECT_EQ(MatchBruteForce(query, a.row(1), {100, 1.0, false}).size(), 2u);
  EXPECT_TRUE(MatchBruteForce(cv::Mat(), train).empty());
  EXPECT_THROW(MatchBruteForce(cv::Mat(2, 16, CV_8UC1), train), InputError);
  EXPECT_THROW(MatchBruteForce(a, train, {100, 0.0, true}), InputError);
}

TEST(KeypointGrid, QueriesAgreeWithBruteForce) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> ux(-20.f, 660.f), uy(-20.f, 500.f), ur(0.f, 60.f);
  std::vector<cv::KeyPoint> kps;
  for (int i = 0; i < 2000; ++i) {
    cv::KeyPoint kp(ux(rng), uy(rng), 31.f);
    kp.octave = static_cast<int>(rng() % 8);
    kps.push_back(kp);
  }
  const KeypointGrid grid(kps, cv::Size(640, 480), 10.f);
  EXPECT_EQ(grid.NumKeypoints(), 2000);
  std::vector<int> got;
  for (int q = 0; q < 500; ++q) {
    const float x = ux(rng), y = uy(rng), r = ur(rng);
    const int min_level = static_cast<int>(rng() % 4);
    const int max_level = (q % 3 == 0) ? -1 : min_level + static_cast<int>(rng() % 4);
    grid.FindInRadius(x, y, r, &got, min_level, max_level);
    std::vector<int> want;
    for (int i = 0; i < 2000; ++i) {
      const float dx = kps[i].pt.x - x, dy = kps[i].pt.y - y;
      if (dx * dx + dy * dy <= r * r && kps[i].octave >= min_level &&
          (max_level < 0 || kps[i].octave <= max_level)) {
        want.push_back(i);
      }
    }
    ASSERT_EQ(got, want) << "query " << q;
  }
  EXPECT_TRUE(grid.FindInRadius(1e6f, 1e6f, 5.f).empty());
  EXPECT_THROW(KeypointGrid(kps, cv::Size(0, 480)), InputError);
}

}  // namespace
}  // namespace dynorb
