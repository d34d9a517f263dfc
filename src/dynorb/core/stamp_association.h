// The timestamp association rule of the TUM RGB-D benchmark's associate.py (Sturm et al., IROS
// 2012), shared by the dataset reader (rgb ↔ depth) and the evaluator (ground truth ↔ estimate):
//
//   candidates = all (i, j) with |first[i] - (second[j] + offset_s)| < max_difference_s
//   sort candidates by (difference, first stamp, second stamp); accept greedily when neither
//   stamp is used yet; return the accepted pairs sorted by (first stamp, second stamp).
//
// Computed in O((n + m) log(n + m)) whatever the window: the smallest remaining difference is
// always between two neighbours of opposite kind in the merged, sorted list of the still
// unmatched stamps, so a heap of neighbouring pairs reproduces the greedy order without listing
// every candidate. Stamps within a list must be distinct; the lists need not be sorted.
// Validation of the inputs is the caller's (its messages name its own options). Pure, thread-safe.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace dynorb {

// (i into first, j into second) pairs.
std::vector<std::pair<size_t, size_t>> AssociateNearestStamps(const std::vector<double>& first,
                                                              const std::vector<double>& second,
                                                              double max_difference_s,
                                                              double offset_s);

}  // namespace dynorb
