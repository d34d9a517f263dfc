#include "dynorb/io/association.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

#include "dynorb/core/error.h"
#include "dynorb/io/text_lines.h"

namespace dynorb {
namespace {

struct Candidate {
  double difference;
  double first_stamp;
  double second_stamp;
  size_t i;
  size_t j;
};

void CheckIncreasing(const std::string& path, int line_no, double previous, double current,
                     bool has_previous) {
  if (!has_previous || current > previous) return;
  throw InputErrorAt(path, line_no,
                     current == previous ? "duplicate timestamp " + std::to_string(current)
                                         : "timestamps are not increasing");
}

}  // namespace

void AssociationOptions::Validate() const {
  if (!std::isfinite(max_difference_s) || max_difference_s <= 0.0) {
    throw InputError("association: max_difference_s must be > 0, got " +
                     std::to_string(max_difference_s));
  }
  if (!std::isfinite(offset_s)) throw InputError("association: offset_s must be finite");
}

std::vector<std::pair<size_t, size_t>> AssociateTimestamps(const std::vector<double>& first,
                                                           const std::vector<double>& second,
                                                           const AssociationOptions& options) {
  options.Validate();
  const double max_diff = options.max_difference_s;
  // Shifted second stamps, sorted. Floating-point addition and subtraction are monotone, so the
  // predicates below are monotone along the sorted order and binary search finds the exact window
  // of associate.py's condition abs(a - (b + offset)) < max_difference.
  std::vector<size_t> order(second.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::vector<double> shifted(second.size());
  for (size_t j = 0; j < second.size(); ++j) shifted[j] = second[j] + options.offset_s;
  std::sort(order.begin(), order.end(),
            [&](size_t x, size_t y) { return shifted[x] < shifted[y]; });

  std::vector<Candidate> candidates;
  for (size_t i = 0; i < first.size(); ++i) {
    const double a = first[i];
    // First position where a - c < max_diff (c too small before it).
    auto begin = std::partition_point(order.begin(), order.end(),
                                      [&](size_t j) { return !(a - shifted[j] < max_diff); });
    for (auto it = begin; it != order.end(); ++it) {
      const double c = shifted[*it];
      if (!(c - a < max_diff)) break;  // all further c are even larger
      const double difference = std::abs(a - c);
      if (difference < max_diff) candidates.push_back({difference, a, second[*it], i, *it});
    }
  }
  // Python sorts tuples (diff, a, b): ties broken by the first, then the second stamp.
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return std::tie(x.difference, x.first_stamp, x.second_stamp) <
           std::tie(y.difference, y.first_stamp, y.second_stamp);
  });
  std::vector<char> used_first(first.size(), 0), used_second(second.size(), 0);
  std::vector<std::pair<size_t, size_t>> matches;
  for (const Candidate& c : candidates) {
    if (used_first[c.i] || used_second[c.j]) continue;
    used_first[c.i] = used_second[c.j] = 1;
    matches.emplace_back(c.i, c.j);
  }
  std::sort(matches.begin(), matches.end(), [&](const auto& x, const auto& y) {
    return std::tie(first[x.first], second[x.second]) < std::tie(first[y.first], second[y.second]);
  });
  return matches;
}

std::vector<StampedPath> ReadImageList(const std::string& path) {
  std::vector<StampedPath> list;
  ForEachDataLine(path, [&](int line_no, const std::vector<std::string>& fields) {
    if (fields.size() != 2) {
      throw InputErrorAt(
          path, line_no,
          "expected 'timestamp path', got " + std::to_string(fields.size()) + " fields");
    }
    const double stamp = ParseDouble(fields[0], path, line_no);
    CheckIncreasing(path, line_no, list.empty() ? 0.0 : list.back().timestamp_s, stamp,
                    !list.empty());
    list.push_back({stamp, fields[1]});
  });
  return list;
}

std::vector<AssociatedPair> ReadAssociationsFile(const std::string& path) {
  std::vector<AssociatedPair> pairs;
  ForEachDataLine(path, [&](int line_no, const std::vector<std::string>& fields) {
    if (fields.size() != 4) {
      throw InputErrorAt(path, line_no,
                         "expected 'rgb_timestamp rgb_path depth_timestamp depth_path', got " +
                             std::to_string(fields.size()) + " fields");
    }
    AssociatedPair pair;
    pair.rgb_timestamp_s = ParseDouble(fields[0], path, line_no);
    pair.rgb_path = fields[1];
    pair.depth_timestamp_s = ParseDouble(fields[2], path, line_no);
    pair.depth_path = fields[3];
    CheckIncreasing(path, line_no, pairs.empty() ? 0.0 : pairs.back().rgb_timestamp_s,
                    pair.rgb_timestamp_s, !pairs.empty());
    pairs.push_back(std::move(pair));
  });
  if (pairs.empty()) throw InputError(path + ": no associations in file");
  return pairs;
}

std::vector<AssociatedPair> AssociateImageLists(const std::vector<StampedPath>& rgb,
                                                const std::vector<StampedPath>& depth,
                                                const AssociationOptions& options) {
  std::vector<double> rgb_stamps, depth_stamps;
  rgb_stamps.reserve(rgb.size());
  depth_stamps.reserve(depth.size());
  for (const StampedPath& s : rgb) rgb_stamps.push_back(s.timestamp_s);
  for (const StampedPath& s : depth) depth_stamps.push_back(s.timestamp_s);
  std::vector<AssociatedPair> pairs;
  for (const auto& [i, j] : AssociateTimestamps(rgb_stamps, depth_stamps, options)) {
    pairs.push_back({rgb[i].timestamp_s, rgb[i].path, depth[j].timestamp_s, depth[j].path});
  }
  if (pairs.empty()) {
    throw InputError("no rgb/depth associations found within max_difference_s = " +
                     std::to_string(options.max_difference_s) + " s (" +
                     std::to_string(rgb.size()) + " rgb, " + std::to_string(depth.size()) +
                     " depth stamps)");
  }
  return pairs;
}

}  // namespace dynorb
