#include "dynorb/features/brief_learning.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>

#include "dynorb/features/orb_descriptor.h"

namespace dynorb {
namespace {

// Offline code: portable popcount (no ifunc/target_clones, which sanitizer builds cannot load).
int64_t CountBoth(const uint64_t* a, const uint64_t* b, int n_words) {
  int64_t n = 0;
  for (int w = 0; w < n_words; ++w) n += __builtin_popcountll(a[w] & b[w]);
  return n;
}

int64_t CountOnes(const std::vector<uint64_t>& a) {
  return CountBoth(a.data(), a.data(), static_cast<int>(a.size()));
}

}  // namespace

double TestOutcomes::Mean(int test) const {
  return n_samples == 0 ? 0.0 : static_cast<double>(CountOnes(tests[test])) / n_samples;
}

static double AbsCorrelationWithMeans(const TestOutcomes& o, int a, int b, double pa, double pb) {
  const double var = pa * (1 - pa) * pb * (1 - pb);
  if (var <= 0.0) return 0.0;
  const int n_words = static_cast<int>(std::min(o.tests[a].size(), o.tests[b].size()));
  const double pab =
      static_cast<double>(CountBoth(o.tests[a].data(), o.tests[b].data(), n_words)) / o.n_samples;
  return std::abs(pab - pa * pb) / std::sqrt(var);
}

double TestOutcomes::AbsCorrelation(int a, int b) const {
  return AbsCorrelationWithMeans(*this, a, b, Mean(a), Mean(b));
}

void AppendTestOutcomes(const KeypointSet& set, const std::vector<BriefPair>& candidates,
                        TestOutcomes* outcomes) {
  const int n_tests = static_cast<int>(candidates.size());
  if (outcomes->tests.size() != candidates.size()) outcomes->tests.assign(n_tests, {});
  std::vector<cv::Mat> blurred(set.pyramid ? set.pyramid->NumLevels() : 0);
  std::vector<uint8_t> bits((n_tests + 7) / 8);
  for (int k = 0; k < set.size(); ++k) {
    const int l = set.keypoints[k].octave;
    if (blurred[l].empty()) {
      cv::GaussianBlur(set.pyramid->Level(l), blurred[l], cv::Size(7, 7), 2.0, 2.0,
                       cv::BORDER_REFLECT_101);
    }
    ComputeSteeredTests(blurred[l], set.level_pixels[k], set.keypoints[k].angle, candidates.data(),
                        n_tests, bits.data());
    const int s = outcomes->n_samples++;
    for (int c = 0; c < n_tests; ++c) {
      std::vector<uint64_t>& column = outcomes->tests[c];
      if (static_cast<int>(column.size()) <= s / 64) column.push_back(0);
      if ((bits[c / 8] >> (c % 8)) & 1) column[s / 64] |= uint64_t{1} << (s % 64);
    }
  }
}

std::vector<int> SelectUncorrelatedTests(const TestOutcomes& outcomes,
                                         const BriefLearningOptions& options) {
  const int n_tests = static_cast<int>(outcomes.tests.size());
  std::vector<double> mean(n_tests);
  std::vector<int> order;
  for (int c = 0; c < n_tests; ++c) {
    mean[c] = outcomes.Mean(c);
    if (mean[c] > 0.0 && mean[c] < 1.0 && std::abs(mean[c] - 0.5) <= options.max_mean_deviation) {
      order.push_back(c);
    }
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return std::abs(mean[a] - 0.5) < std::abs(mean[b] - 0.5); });
  if (static_cast<int>(order.size()) <= options.n_select) return order;
  std::vector<int> selected;
  for (double threshold = options.initial_threshold; threshold <= 1.0 + 1e-9;
       threshold += options.threshold_step) {
    selected.assign(1, order[0]);
    for (size_t i = 1; i < order.size() && static_cast<int>(selected.size()) < options.n_select;
         ++i) {
      bool ok = true;
      for (int s : selected) {
        if (AbsCorrelationWithMeans(outcomes, order[i], s, mean[order[i]], mean[s]) >= threshold) {
          ok = false;
          break;
        }
      }
      if (ok) selected.push_back(order[i]);
    }
    if (static_cast<int>(selected.size()) == options.n_select) break;
  }
  return selected;
}

}  // namespace dynorb
