#include "dynorb/dynamic/morphology.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

namespace dynorb {
namespace {

// Half-width of each row of the (2r+1)-square elliptic element, -1 for an empty row; every
// non-empty row of OpenCV's ellipse is a run centred on the anchor column (checked).
std::vector<int> EllipseRowHalfWidths(int radius_px) {
  const int size = 2 * radius_px + 1;
  const cv::Mat element = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(size, size));
  std::vector<int> half(size, -1);
  for (int i = 0; i < size; ++i) {
    const uint8_t* row = element.ptr<uint8_t>(i);
    int first = -1, last = -1;
    for (int j = 0; j < size; ++j) {
      if (row[j] == 0) continue;
      if (first < 0) first = j;
      last = j;
    }
    if (first < 0) continue;
    CV_Assert(first + last == 2 * radius_px && std::count(row + first, row + last + 1, 0) == 0);
    half[i] = radius_px - first;
  }
  return half;
}

struct MaxOp {
  static constexpr uint8_t kIdentity = 0;
  static uint8_t Apply(uint8_t a, uint8_t b) { return a > b ? a : b; }
  static cv::v_uint8x16 Apply(const cv::v_uint8x16& a, const cv::v_uint8x16& b) {
    return cv::v_max(a, b);
  }
};
struct MinOp {
  static constexpr uint8_t kIdentity = 255;
  static uint8_t Apply(uint8_t a, uint8_t b) { return a < b ? a : b; }
  static cv::v_uint8x16 Apply(const cv::v_uint8x16& a, const cv::v_uint8x16& b) {
    return cv::v_min(a, b);
  }
};

// The two passes, 16 pixels at a time (OpenCV's universal intrinsics; SSE2 / NEON baseline):
// out[x] = op(previous[x], op(left[x], right[x])) and out[x] = op(out[x], in[x]).
template <class Op>
void CombineThree(const uint8_t* previous, const uint8_t* left, const uint8_t* right, uint8_t* out,
                  int n) {
  int x = 0;
  for (; x + 16 <= n; x += 16) {
    cv::v_store(out + x, Op::Apply(cv::v_load(previous + x),
                                   Op::Apply(cv::v_load(left + x), cv::v_load(right + x))));
  }
  for (; x < n; ++x) out[x] = Op::Apply(previous[x], Op::Apply(left[x], right[x]));
}
template <class Op>
void CombineTwo(const uint8_t* in, uint8_t* out, int n) {
  int x = 0;
  for (; x + 16 <= n; x += 16)
    cv::v_store(out + x, Op::Apply(cv::v_load(out + x), cv::v_load(in + x)));
  for (; x < n; ++x) out[x] = Op::Apply(out[x], in[x]);
}

template <class Op>
void MorphEllipse(const cv::Mat& src, int radius_px, cv::Mat* dst) {
  CV_Assert(dst != nullptr && src.type() == CV_8U && radius_px >= 0);
  if (radius_px == 0 || src.empty()) {
    src.copyTo(*dst);
    return;
  }
  const std::vector<int> half = EllipseRowHalfWidths(radius_px);
  const int max_w = *std::max_element(half.begin(), half.end());
  // Row buffers are `stride` wide (a multiple of 16: no scalar tails; the extra columns see the
  // identity padding and are never copied out).
  const int rows = src.rows, cols = src.cols, stride = (cols + 15) / 16 * 16;
  const int padded_cols = stride + 2 * max_w;
  // slot[w]: where the running extremum of half-width w is kept (-1: no element row needs it).
  std::vector<int> slot(max_w + 1, -1);
  int slots = 0;
  for (int w : half) {
    if (w >= 0 && slot[w] < 0) slot[w] = slots++;
  }
  // The running extrema of the source rows y - r .. y + r, in a ring of 2r + 1 rows per slot.
  const int ring = 2 * radius_px + 1;
  std::vector<uint8_t> line(padded_cols, Op::kIdentity), scratch(2 * stride), accumulated(stride);
  std::vector<uint8_t> horizontal(static_cast<size_t>(slots) * ring * stride);
  auto stored = [&](int w, int y) {
    return horizontal.data() + (static_cast<size_t>(slot[w]) * ring + y % ring) * stride;
  };
  // Half-width w's extremum from w - 1's, written where it is kept (or to a scratch row).
  auto compute_row = [&](int y) {
    const uint8_t* in = src.ptr<uint8_t>(y);
    std::copy(in, in + cols, line.begin() + max_w);
    const uint8_t* previous = line.data() + max_w;
    if (slot[0] >= 0) std::copy(previous, previous + stride, stored(0, y));
    for (int w = 1; w <= max_w; ++w) {
      uint8_t* out = slot[w] >= 0 ? stored(w, y) : scratch.data() + (w % 2) * stride;
      CombineThree<Op>(previous, line.data() + max_w - w, line.data() + max_w + w, out, stride);
      previous = out;
    }
  };
  // Rows are read in full before any output row is written, except the source rows still to be
  // computed: dst may be src, so the result goes to a separate image when they share memory.
  cv::Mat out_image;
  const bool aliased =
      dst->data != nullptr && dst->datastart <= src.dataend && src.datastart <= dst->dataend;
  if (aliased) {
    out_image.create(rows, cols, CV_8U);
  } else {
    dst->create(rows, cols, CV_8U);
    out_image = *dst;
  }
  int computed = 0;  // source rows [0, computed) are in the ring
  for (int y = 0; y < rows; ++y) {
    for (; computed < std::min(rows, y + radius_px + 1); ++computed) compute_row(computed);
    std::fill(accumulated.begin(), accumulated.end(), Op::kIdentity);
    for (int i = 0; i < ring; ++i) {
      const int source_y = y + i - radius_px;
      if (half[i] < 0 || source_y < 0 || source_y >= rows) continue;
      CombineTwo<Op>(stored(half[i], source_y), accumulated.data(), stride);
    }
    std::copy(accumulated.begin(), accumulated.begin() + cols, out_image.ptr<uint8_t>(y));
  }
  if (aliased) {
    dst->create(rows, cols, CV_8U);
    out_image.copyTo(*dst);
  }
}

}  // namespace

void DilateEllipse(const cv::Mat& src, int radius_px, cv::Mat* dst) {
  MorphEllipse<MaxOp>(src, radius_px, dst);
}

void ErodeEllipse(const cv::Mat& src, int radius_px, cv::Mat* dst) {
  MorphEllipse<MinOp>(src, radius_px, dst);
}

void CloseEllipse(const cv::Mat& src, int radius_px, cv::Mat* dst) {
  cv::Mat dilated;
  DilateEllipse(src, radius_px, &dilated);
  ErodeEllipse(dilated, radius_px, dst);
}

}  // namespace dynorb
