// Timestamp lists and RGB-depth association for TUM RGB-D style datasets.
//
// Image lists (rgb.txt, depth.txt): one "timestamp relative/path.png" per line, '#' comments and
// blank lines allowed, strictly increasing timestamps.
// Associations files (ORB-SLAM2 style): "rgb_ts rgb/x.png depth_ts depth/x.png" per line.
//
// AssociateTimestamps() implements exactly the rule of TUM's associate.py:
//   candidates = all (i, j) with |first[i] - (second[j] + offset)| < max_difference,
//   sorted by (difference, first stamp, second stamp); greedily accept a candidate when neither
//   stamp has been used yet; finally sort the accepted pairs by the first stamp.
// It runs in O((n + m) log(n + m)) (core/stamp_association.h, shared with the evaluator) instead
// of associate.py's O(n*m). Stateless free functions, thread-safe.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace dynorb {

struct StampedPath {
  double timestamp_s = 0.0;
  std::string path;  // as written in the list file (usually relative to the sequence folder)
};

struct AssociatedPair {
  double rgb_timestamp_s = 0.0;
  std::string rgb_path;
  double depth_timestamp_s = 0.0;
  std::string depth_path;
};

struct AssociationOptions {
  // Maximum |t_first - (t_second + offset_s)| for two stamps to be associated (strict '<').
  double max_difference_s = 0.02;
  // Added to every stamp of the second list before comparing (associate.py --offset).
  double offset_s = 0.0;
  // Throws InputError unless max_difference_s > 0 and both values are finite.
  void Validate() const;
};

// Returns index pairs (i into `first`, j into `second`) sorted by first[i]. Stamps in each list
// must be unique (the list readers guarantee it); the lists need not be sorted.
std::vector<std::pair<size_t, size_t>> AssociateTimestamps(const std::vector<double>& first,
                                                           const std::vector<double>& second,
                                                           const AssociationOptions& options = {});

// Reads an rgb.txt/depth.txt style list. Throws InputError (file:line) for a missing file, a line
// without exactly "timestamp path", a bad number, or a duplicate / decreasing timestamp.
std::vector<StampedPath> ReadImageList(const std::string& path);

// Reads an associations file. Throws InputError (file:line) for a missing file, a line without
// exactly 4 fields, a bad number, or duplicate / decreasing rgb timestamps. An empty file is an
// error ("no associations").
std::vector<AssociatedPair> ReadAssociationsFile(const std::string& path);

// Associates two image lists (rgb first, depth second). Throws InputError if nothing associates.
std::vector<AssociatedPair> AssociateImageLists(const std::vector<StampedPath>& rgb,
                                                const std::vector<StampedPath>& depth,
                                                const AssociationOptions& options = {});

}  // namespace dynorb
