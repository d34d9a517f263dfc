#include "dynorb/io/association.h"

#include <cmath>

#include "dynorb/core/error.h"
#include "dynorb/core/stamp_association.h"
#include "dynorb/io/text_lines.h"
#include "dynorb/io/timestamp_check.h"

namespace dynorb {
namespace {

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
  return AssociateNearestStamps(first, second, options.max_difference_s, options.offset_s);
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
    CheckTimestampRange(stamp, fields[0], path, line_no);
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
    CheckTimestampRange(pair.rgb_timestamp_s, fields[0], path, line_no);
    pair.rgb_path = fields[1];
    pair.depth_timestamp_s = ParseDouble(fields[2], path, line_no);
    CheckTimestampRange(pair.depth_timestamp_s, fields[2], path, line_no);
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
