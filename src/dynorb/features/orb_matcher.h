// Descriptor matching utilities for 256-bit ORB descriptors and a keypoint grid for projection
// search.
//
// Descriptors are rows of a CV_8UC1 cv::Mat with kBriefBytes (32) columns, as produced by
// OrbExtractor. All functions are pure and thread-safe; a KeypointGrid is immutable after
// construction and may be queried concurrently.
#pragma once

#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <vector>

#include "dynorb/features/brief_pattern.h"

namespace dynorb {

// Set bits of a 64-bit word. Without -mpopcnt (Debian's amd64 baseline) __builtin_popcountll is
// an out-of-line libgcc call that cost 6 % of a whole SLAM run; the inline SWAR sum is branch-free.
inline int Popcount64(uint64_t x) {
#if defined(__POPCNT__)
  return __builtin_popcountll(x);
#else
  x = x - ((x >> 1) & 0x5555555555555555ULL);
  x = (x & 0x3333333333333333ULL) + ((x >> 2) & 0x3333333333333333ULL);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0fULL;
  return static_cast<int>((x * 0x0101010101010101ULL) >> 56);
#endif
}

// Number of differing bits between two 256-bit descriptors (4 × 64-bit popcount).
inline int HammingDistance256(const uint8_t* a, const uint8_t* b) {
  int distance = 0;
  for (int w = 0; w < kBriefBytes / 8; ++w) {
    uint64_t wa, wb;
    std::memcpy(&wa, a + 8 * w, 8);
    std::memcpy(&wb, b + 8 * w, 8);
    distance += Popcount64(wa ^ wb);
  }
  return distance;
}

// Distance between row `row_a` of `a` and row `row_b` of `b` (CV_8UC1, 32 columns each).
inline int HammingDistance256(const cv::Mat& a, int row_a, const cv::Mat& b, int row_b) {
  return HammingDistance256(a.ptr<uint8_t>(row_a), b.ptr<uint8_t>(row_b));
}

struct BruteForceMatchOptions {
  int max_distance = 100;    // reject matches with a larger Hamming distance (ORB-SLAM TH_HIGH)
  double max_ratio = 0.8;    // keep if best < max_ratio · second best (1 disables the ratio test)
  bool mutual_check = true;  // keep only if the query is also the train descriptor's best match

  // Throws InputError on out-of-range values.
  void Validate() const;
};

struct DescriptorMatch {
  int query_index = -1;
  int train_index = -1;
  int distance = 0;
};

// For each query row, the nearest train row under the options' tests. Ties resolve to the lowest
// index. The ratio test compares the best and second-best train rows of the query (with a single
// train row it always passes). Result ordered by query_index. Throws InputError if a matrix is not
// CV_8UC1 with kBriefBytes columns (an empty matrix gives no matches).
std::vector<DescriptorMatch> MatchBruteForce(const cv::Mat& query, const cv::Mat& train,
                                             const BruteForceMatchOptions& options = {});

// Uniform grid over the image holding keypoint indices, for "which keypoints lie within r pixels
// of (x, y)" queries (projection search in tracking). Keypoints outside the image are kept in the
// nearest border cell, so queries stay exact. Owns a copy of the positions and levels it needs.
class KeypointGrid {
 public:
  // cell_size_px > 0; image_size non-empty.
  KeypointGrid(const std::vector<cv::KeyPoint>& keypoints, cv::Size image_size,
               float cell_size_px = 10.f);

  // Indices (ascending) of keypoints with (kp.x − x)² + (kp.y − y)² ≤ radius_px² and
  // min_level ≤ octave ≤ max_level (max_level < 0: no upper bound). Clears `out` first.
  void FindInRadius(float x, float y, float radius_px, std::vector<int>* out, int min_level = 0,
                    int max_level = -1) const;
  std::vector<int> FindInRadius(float x, float y, float radius_px, int min_level = 0,
                                int max_level = -1) const;

  int NumKeypoints() const { return static_cast<int>(points_.size()); }

 private:
  int CellX(float x) const;
  int CellY(float y) const;

  float inv_cell_size_;
  int n_cols_, n_rows_;
  std::vector<cv::Point2f> points_;
  std::vector<int> levels_;
  std::vector<int> cell_start_;  // CSR: indices of cell c are cell_items_[cell_start_[c] .. [c+1])
  std::vector<int> cell_items_;
};

}  // namespace dynorb
