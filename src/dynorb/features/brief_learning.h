// Learning a steered-BRIEF test pattern: the greedy rBRIEF procedure of Rublee et al., "ORB: an
// efficient alternative to SIFT or SURF", ICCV 2011, §4.3, implemented from the paper.
//
// 1. Run every candidate test on every training keypoint (steered by the keypoint's angle, on the
//    blurred level) → one binary column per test.
// 2. Order the tests by |mean − 0.5| (most balanced first).
// 3. Greedy: take the first; take each next test whose |Pearson correlation| with every test
//    taken so far is below a threshold. If fewer than n_select were taken, raise the threshold and
//    start again.
//
// Offline tool code (used to produce brief_pattern_table.inc); not used at run time.
// Pure functions; thread-safe.
#pragma once

#include <cstdint>
#include <vector>

#include "dynorb/features/brief_pattern.h"
#include "dynorb/features/orb_extractor.h"

namespace dynorb {

// Binary outcomes of candidate tests over training samples: tests[c] is a packed bit column
// (sample s = bit s % 64 of word s / 64).
struct TestOutcomes {
  int n_samples = 0;
  std::vector<std::vector<uint64_t>> tests;

  explicit TestOutcomes(int n_tests = 0) : tests(n_tests) {}
  double Mean(int test) const;
  // |Pearson correlation| of two tests (0 if either is constant).
  double AbsCorrelation(int a, int b) const;
};

// Appends one sample per keypoint of `set` (all candidates evaluated, as Describe() would).
void AppendTestOutcomes(const KeypointSet& set, const std::vector<BriefPair>& candidates,
                        TestOutcomes* outcomes);

struct BriefLearningOptions {
  int n_select = kBriefBits;        // number of tests to select
  double initial_threshold = 0.2;   // first |correlation| bound
  double threshold_step = 0.02;     // increase when too few tests pass
  double max_mean_deviation = 0.5;  // only candidates with |mean − 0.5| ≤ this (0.5: all)
};

// Indices of the selected candidates, in selection order (most balanced first). Returns fewer
// than n_select only if there are not enough non-constant candidates.
std::vector<int> SelectUncorrelatedTests(const TestOutcomes& outcomes,
                                         const BriefLearningOptions& options = {});

}  // namespace dynorb
