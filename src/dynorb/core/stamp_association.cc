#include "dynorb/core/stamp_association.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <queue>
#include <tuple>

namespace dynorb {
namespace {

// One stamp of the merged list; a doubly linked list over the still unmatched stamps.
struct Node {
  double key;    // first[i], or second[j] + offset
  size_t index;  // into its own list
  bool is_first;
  long prev, next;
  bool matched = false;
};

// A pair of neighbouring nodes of opposite kind, ordered like associate.py's sorted tuples.
struct Candidate {
  double diff, first_stamp, second_stamp;
  long first_node, second_node;
  bool operator>(const Candidate& o) const {
    return std::tie(diff, first_stamp, second_stamp) >
           std::tie(o.diff, o.first_stamp, o.second_stamp);
  }
};

std::vector<size_t> SortedOrder(const std::vector<double>& stamps, double shift) {
  std::vector<size_t> order(stamps.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return stamps[a] + shift < stamps[b] + shift; });
  return order;
}

}  // namespace

std::vector<std::pair<size_t, size_t>> AssociateNearestStamps(const std::vector<double>& first,
                                                              const std::vector<double>& second,
                                                              double max_difference_s,
                                                              double offset_s) {
  const std::vector<size_t> first_order = SortedOrder(first, 0.0);
  const std::vector<size_t> second_order = SortedOrder(second, offset_s);
  std::vector<Node> nodes;
  nodes.reserve(first.size() + second.size());
  size_t i = 0, j = 0;
  while (i < first.size() || j < second.size()) {
    const bool take_first =
        j == second.size() ||
        (i < first.size() && first[first_order[i]] <= second[second_order[j]] + offset_s);
    Node node;
    node.is_first = take_first;
    node.index = take_first ? first_order[i++] : second_order[j++];
    node.key = take_first ? first[node.index] : second[node.index] + offset_s;
    node.prev = static_cast<long>(nodes.size()) - 1;
    node.next = static_cast<long>(nodes.size()) + 1;
    nodes.push_back(node);
  }
  if (!nodes.empty()) nodes.back().next = -1;

  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> heap;
  auto push_if_candidate = [&](long a, long b) {
    if (a < 0 || b < 0 || nodes[a].is_first == nodes[b].is_first) return;
    const long f = nodes[a].is_first ? a : b, s = nodes[a].is_first ? b : a;
    const double t_first = first[nodes[f].index], t_second = second[nodes[s].index];
    const double diff = std::abs(t_first - (t_second + offset_s));  // exactly associate.py's
    if (diff < max_difference_s) heap.push({diff, t_first, t_second, f, s});
  };
  for (long n = 0; n + 1 < static_cast<long>(nodes.size()); ++n) push_if_candidate(n, n + 1);

  std::vector<std::pair<size_t, size_t>> pairs;
  while (!heap.empty()) {
    const Candidate c = heap.top();
    heap.pop();
    Node& f = nodes[c.first_node];
    Node& s = nodes[c.second_node];
    if (f.matched || s.matched) continue;
    // Both unmatched: nothing lies between them (only removals happen), so they are neighbours.
    f.matched = s.matched = true;
    pairs.emplace_back(f.index, s.index);
    const long left = std::min(c.first_node, c.second_node),
               right = std::max(c.first_node, c.second_node);
    const long before = nodes[left].prev, after = nodes[right].next;
    if (before >= 0) nodes[before].next = after;
    if (after >= 0) nodes[after].prev = before;
    push_if_candidate(before, after);
  }
  std::sort(pairs.begin(), pairs.end(), [&](const auto& x, const auto& y) {
    return std::tie(first[x.first], second[x.second]) < std::tie(first[y.first], second[y.second]);
  });
  return pairs;
}

}  // namespace dynorb
