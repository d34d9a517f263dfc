#include "dynorb/features/orb_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

// Best and second-best train rows per query row, best query row per train row (lowest index on
// ties). Inlined twice: into a POPCNT-enabled function chosen at run time on CPUs that have the
// instruction, and into a portable one. (Plain runtime dispatch rather than target_clones: an
// ifunc resolver runs before sanitizer runtimes are initialised and crashes TSan builds.)
#if defined(__GNUC__) || defined(__clang__)
#define DYNORB_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define DYNORB_ALWAYS_INLINE inline
#endif

DYNORB_ALWAYS_INLINE void NearestNeighboursKernel(const cv::Mat& query, const cv::Mat& train,
                                                  int* q_best, int* q_best_d, int* q_second_d,
                                                  int* t_best, int* t_best_d) {
  const int nq = query.rows, nt = train.rows;
  for (int t = 0; t < nt; ++t) {
    t_best[t] = -1;
    t_best_d[t] = std::numeric_limits<int>::max();
  }
  for (int q = 0; q < nq; ++q) {
    uint64_t qw[4];
    std::memcpy(qw, query.ptr<uint8_t>(q), 32);
    int best = -1, best_d = std::numeric_limits<int>::max();
    int second_d = std::numeric_limits<int>::max();
    for (int t = 0; t < nt; ++t) {
      uint64_t tw[4];
      std::memcpy(tw, train.ptr<uint8_t>(t), 32);
      const int d = Popcount64(qw[0] ^ tw[0]) + Popcount64(qw[1] ^ tw[1]) + Popcount64(qw[2] ^ tw[2]) +
                    Popcount64(qw[3] ^ tw[3]);
      if (d < best_d) {
        second_d = best_d;
        best_d = d;
        best = t;
      } else if (d < second_d) {
        second_d = d;
      }
      if (d < t_best_d[t]) {
        t_best_d[t] = d;
        t_best[t] = q;
      }
    }
    q_best[q] = best;
    q_best_d[q] = best_d;
    q_second_d[q] = second_d;
  }
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
__attribute__((target("popcnt"))) void NearestNeighboursPopcnt(const cv::Mat& query,
                                                               const cv::Mat& train, int* q_best,
                                                               int* q_best_d, int* q_second_d,
                                                               int* t_best, int* t_best_d) {
  NearestNeighboursKernel(query, train, q_best, q_best_d, q_second_d, t_best, t_best_d);
}

bool CpuHasPopcnt() {
  static const bool kHas = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("popcnt") != 0;
  }();
  return kHas;
}
#endif

void NearestNeighbours(const cv::Mat& query, const cv::Mat& train, int* q_best, int* q_best_d,
                       int* q_second_d, int* t_best, int* t_best_d) {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (CpuHasPopcnt()) {
    NearestNeighboursPopcnt(query, train, q_best, q_best_d, q_second_d, t_best, t_best_d);
    return;
  }
#endif
  NearestNeighboursKernel(query, train, q_best, q_best_d, q_second_d, t_best, t_best_d);
}

void CheckDescriptors(const cv::Mat& m, const char* name) {
  if (m.empty()) return;
  if (m.type() != CV_8UC1 || m.cols != kBriefBytes) {
    throw InputError(std::string("MatchBruteForce: ") + name + " must be CV_8UC1 with " +
                     std::to_string(kBriefBytes) + " columns");
  }
}

}  // namespace

void BruteForceMatchOptions::Validate() const {
  if (max_distance < 0 || max_distance > kBriefBits) {
    throw InputError("BruteForceMatchOptions: max_distance must be in [0, 256], got " +
                     std::to_string(max_distance));
  }
  if (!(max_ratio > 0.0 && max_ratio <= 1.0)) {
    throw InputError("BruteForceMatchOptions: max_ratio must be in (0, 1], got " +
                     std::to_string(max_ratio));
  }
}

std::vector<DescriptorMatch> MatchBruteForce(const cv::Mat& query, const cv::Mat& train,
                                             const BruteForceMatchOptions& options) {
  options.Validate();
  CheckDescriptors(query, "query");
  CheckDescriptors(train, "train");
  if (query.empty() || train.empty()) return {};
  const int nq = query.rows, nt = train.rows;
  std::vector<int> q_best(nq), q_best_d(nq), q_second_d(nq), t_best(nt), t_best_d(nt);
  NearestNeighbours(query, train, q_best.data(), q_best_d.data(), q_second_d.data(), t_best.data(),
                    t_best_d.data());
  std::vector<DescriptorMatch> matches;
  for (int q = 0; q < nq; ++q) {
    const int d = q_best_d[q];
    if (d > options.max_distance) continue;
    if (options.max_ratio < 1.0 && q_second_d[q] != std::numeric_limits<int>::max() &&
        !(d < options.max_ratio * q_second_d[q])) {
      continue;
    }
    if (options.mutual_check && t_best[q_best[q]] != q) continue;
    matches.push_back(DescriptorMatch{q, q_best[q], d});
  }
  return matches;
}

KeypointGrid::KeypointGrid(const std::vector<cv::KeyPoint>& keypoints, cv::Size image_size,
                           float cell_size_px) {
  if (!(cell_size_px > 0.f) || image_size.width <= 0 || image_size.height <= 0) {
    throw InputError("KeypointGrid: cell size and image size must be positive");
  }
  inv_cell_size_ = 1.f / cell_size_px;
  n_cols_ = std::max(1, static_cast<int>(std::ceil(image_size.width * inv_cell_size_)));
  n_rows_ = std::max(1, static_cast<int>(std::ceil(image_size.height * inv_cell_size_)));
  const int n = static_cast<int>(keypoints.size());
  points_.resize(n);
  levels_.resize(n);
  std::vector<int> cell_of(n);
  cell_start_.assign(n_cols_ * n_rows_ + 1, 0);
  for (int i = 0; i < n; ++i) {
    points_[i] = keypoints[i].pt;
    levels_[i] = keypoints[i].octave;
    cell_of[i] = CellY(points_[i].y) * n_cols_ + CellX(points_[i].x);
    ++cell_start_[cell_of[i] + 1];
  }
  for (size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  cell_items_.resize(n);
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (int i = 0; i < n; ++i) cell_items_[fill[cell_of[i]]++] = i;  // ascending within a cell
}

int KeypointGrid::CellX(float x) const {
  const float c = std::floor(x * inv_cell_size_);
  return c < 0.f ? 0 : (c >= n_cols_ ? n_cols_ - 1 : static_cast<int>(c));
}

int KeypointGrid::CellY(float y) const {
  const float c = std::floor(y * inv_cell_size_);
  return c < 0.f ? 0 : (c >= n_rows_ ? n_rows_ - 1 : static_cast<int>(c));
}

void KeypointGrid::FindInRadius(float x, float y, float radius_px, std::vector<int>* out,
                                int min_level, int max_level) const {
  out->clear();
  if (!(radius_px >= 0.f) || !std::isfinite(x) || !std::isfinite(y)) return;
  const float r2 = radius_px * radius_px;
  const int c0 = CellX(x - radius_px), c1 = CellX(x + radius_px);
  const int r0 = CellY(y - radius_px), r1 = CellY(y + radius_px);
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) {
      const int cell = r * n_cols_ + c;
      for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
        const int i = cell_items_[k];
        if (levels_[i] < min_level || (max_level >= 0 && levels_[i] > max_level)) continue;
        const float dx = points_[i].x - x, dy = points_[i].y - y;
        if (dx * dx + dy * dy <= r2) out->push_back(i);
      }
    }
  }
  std::sort(out->begin(), out->end());
}

std::vector<int> KeypointGrid::FindInRadius(float x, float y, float radius_px, int min_level,
                                            int max_level) const {
  std::vector<int> out;
  FindInRadius(x, y, radius_px, &out, min_level, max_level);
  return out;
}

}  // namespace dynorb
