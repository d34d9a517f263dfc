#include "dynorb/eval/association.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <queue>
#include <string>
#include <tuple>

#include "dynorb/core/error.h"
#include "dynorb/eval/text_format.h"

namespace dynorb {
namespace {

void CheckIncreasing(const std::vector<double>& stamps, const char* what) {
  for (size_t i = 1; i < stamps.size(); ++i) {
    if (!(stamps[i] > stamps[i - 1])) {
      throw InputError(std::string(what) + " timestamps must be strictly increasing (index " +
                       std::to_string(i) + ")");
    }
  }
}

// One stamp in the merged list; a doubly linked list over the unmatched stamps.
struct Node {
  double key;  // t_gt, or t_est + offset
  int index;   // index into its own trajectory
  bool is_gt;
  int prev, next;
  bool matched = false;
};

// A candidate pair of neighbouring nodes, ordered like associate.py's sorted tuples.
struct Candidate {
  double diff, gt_stamp, est_stamp;
  int gt_node, est_node;
  bool operator>(const Candidate& o) const {
    return std::tie(diff, gt_stamp, est_stamp) > std::tie(o.diff, o.gt_stamp, o.est_stamp);
  }
};

}  // namespace

void StampAssociationOptions::Validate() const {
  if (!(max_diff_s > 0.0) || !std::isfinite(max_diff_s)) {
    throw InputError("--max-diff must be a positive number of seconds, got " +
                     ShortNumber(max_diff_s));
  }
  if (!std::isfinite(offset_s)) throw InputError("--offset must be finite");
}

std::vector<IndexPair> AssociateStamps(const std::vector<double>& gt_stamps_s,
                                       const std::vector<double>& est_stamps_s,
                                       const StampAssociationOptions& options) {
  options.Validate();
  CheckIncreasing(gt_stamps_s, "ground-truth");
  CheckIncreasing(est_stamps_s, "estimate");

  // Merge both sorted stamp lists into one list ordered by key.
  std::vector<Node> nodes;
  nodes.reserve(gt_stamps_s.size() + est_stamps_s.size());
  size_t i = 0, j = 0;
  while (i < gt_stamps_s.size() || j < est_stamps_s.size()) {
    const bool take_gt =
        j == est_stamps_s.size() ||
        (i < gt_stamps_s.size() && gt_stamps_s[i] <= est_stamps_s[j] + options.offset_s);
    Node node;
    node.is_gt = take_gt;
    node.index = static_cast<int>(take_gt ? i++ : j++);
    node.key = take_gt ? gt_stamps_s[node.index] : est_stamps_s[node.index] + options.offset_s;
    node.prev = static_cast<int>(nodes.size()) - 1;
    node.next = static_cast<int>(nodes.size()) + 1;
    nodes.push_back(node);
  }
  if (!nodes.empty()) nodes.back().next = -1;

  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> heap;
  auto push_if_candidate = [&](int a, int b) {
    if (a < 0 || b < 0 || nodes[a].is_gt == nodes[b].is_gt) return;
    const Node& g = nodes[a].is_gt ? nodes[a] : nodes[b];
    const Node& e = nodes[a].is_gt ? nodes[b] : nodes[a];
    const double t_gt = gt_stamps_s[g.index];
    const double t_est = est_stamps_s[e.index];
    const double diff = std::abs(t_gt - (t_est + options.offset_s));  // exactly associate.py's
    if (diff < options.max_diff_s)
      heap.push({diff, t_gt, t_est, nodes[a].is_gt ? a : b, nodes[a].is_gt ? b : a});
  };
  for (int n = 0; n + 1 < static_cast<int>(nodes.size()); ++n) push_if_candidate(n, n + 1);

  std::vector<IndexPair> pairs;
  while (!heap.empty()) {
    const Candidate c = heap.top();
    heap.pop();
    Node& g = nodes[c.gt_node];
    Node& e = nodes[c.est_node];
    if (g.matched || e.matched) continue;
    // Both unmatched: nothing lies between them (only removals happen), so they are neighbours.
    g.matched = e.matched = true;
    pairs.push_back({g.index, e.index});
    const int left = std::min(c.gt_node, c.est_node);
    const int right = std::max(c.gt_node, c.est_node);
    const int before = nodes[left].prev;
    const int after = nodes[right].next;
    if (before >= 0) nodes[before].next = after;
    if (after >= 0) nodes[after].prev = before;
    push_if_candidate(before, after);
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const IndexPair& a, const IndexPair& b) { return a.gt < b.gt; });
  return pairs;
}

std::vector<double> Stamps(const Trajectory& trajectory) {
  std::vector<double> stamps;
  stamps.reserve(trajectory.size());
  for (const StampedPose& pose : trajectory) stamps.push_back(pose.timestamp_s);
  return stamps;
}

std::vector<IndexPair> AssociateTrajectories(const Trajectory& gt, const Trajectory& est,
                                             const StampAssociationOptions& options) {
  return AssociateStamps(Stamps(gt), Stamps(est), options);
}

}  // namespace dynorb
