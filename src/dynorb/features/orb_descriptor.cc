#include "dynorb/features/orb_descriptor.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

#include "dynorb/core/angles.h"
#include "dynorb/features/brief_pattern.h"
#include "dynorb/features/image_pyramid.h"

namespace dynorb {
namespace {

constexpr int kDiscRadius2 = 240;  // u² + v² ≤ 240: the ORB disc of radius ≈ 15.5 px

// Half-width of the disc on each row |v| ≤ kHalfPatchSize. Symmetric under u ↔ v by construction.
std::array<int, kHalfPatchSize + 1> DiscHalfWidths() {
  std::array<int, kHalfPatchSize + 1> u_max{};
  for (int v = 0; v <= kHalfPatchSize; ++v) {
    int u = 0;
    while ((u + 1) * (u + 1) + v * v <= kDiscRadius2) ++u;
    u_max[v] = u;
  }
  return u_max;
}

}  // namespace

float IntensityCentroidAngleDeg(const cv::Mat& level, cv::Point center) {
  static const std::array<int, kHalfPatchSize + 1> kUMax = DiscHalfWidths();
  assert(level.type() == CV_8UC1);
  assert(center.x >= kHalfPatchSize && center.x < level.cols - kHalfPatchSize);
  assert(center.y >= kHalfPatchSize && center.y < level.rows - kHalfPatchSize);
  const uint8_t* c = level.ptr<uint8_t>(center.y) + center.x;
  const int step = static_cast<int>(level.step1());
  int m10 = 0, m01 = 0;
  for (int u = -kUMax[0]; u <= kUMax[0]; ++u) m10 += u * c[u];  // centre row: v = 0
  for (int v = 1; v <= kHalfPatchSize; ++v) {
    // Rows +v and −v together: Σ u (I₊ + I₋) for m10 and v Σ (I₊ − I₋) for m01.
    const uint8_t* below = c + v * step;
    const uint8_t* above = c - v * step;
    int diff_sum = 0;
    for (int u = -kUMax[v]; u <= kUMax[v]; ++u) {
      const int lo = below[u], hi = above[u];
      m10 += u * (lo + hi);
      diff_sum += lo - hi;
    }
    m01 += v * diff_sum;
  }
  float angle = static_cast<float>(std::atan2(static_cast<double>(m01), static_cast<double>(m10)) *
                                   (180.0 / CV_PI));
  if (angle < 0.f) angle += 360.f;
  if (angle >= 360.f) angle -= 360.f;
  return angle;
}

void ComputeSteeredTests(const cv::Mat& blurred, cv::Point center, float angle_deg,
                         const BriefPair* pairs, int n, uint8_t* out) {
  assert(blurred.type() == CV_8UC1);
  assert(center.x > kBriefMaxRadius && center.x < blurred.cols - kBriefMaxRadius - 1);
  assert(center.y > kBriefMaxRadius && center.y < blurred.rows - kBriefMaxRadius - 1);
  const double angle_rad = angle_deg * kRadPerDeg;
  const float a = static_cast<float>(std::cos(angle_rad));
  const float b = static_cast<float>(std::sin(angle_rad));
  const uint8_t* c = blurred.ptr<uint8_t>(center.y) + center.x;
  const int step = static_cast<int>(blurred.step1());
  // Rotated, rounded offsets of both points of a block of pairs first (a loop the compiler
  // vectorises), then the comparisons.
  constexpr int kBlock = 64;
  int offset1[kBlock], offset2[kBlock];
  for (int start = 0; start < n; start += kBlock) {
    const int count = std::min(kBlock, n - start);
    const BriefPair* p = pairs + start;
    for (int i = 0; i < count; ++i) {
      offset1[i] = cvRound(p[i].x1 * b + p[i].y1 * a) * step + cvRound(p[i].x1 * a - p[i].y1 * b);
      offset2[i] = cvRound(p[i].x2 * b + p[i].y2 * a) * step + cvRound(p[i].x2 * a - p[i].y2 * b);
    }
    for (int i = 0; i < count; i += 8) {
      uint8_t value = 0;
      for (int bit = 0; bit < 8 && i + bit < count; ++bit) {
        value |= static_cast<uint8_t>((c[offset1[i + bit]] < c[offset2[i + bit]]) << bit);
      }
      out[(start + i) / 8] = value;
    }
  }
}

void ComputeSteeredBrief(const cv::Mat& blurred, cv::Point center, float angle_deg, uint8_t* out) {
  ComputeSteeredTests(blurred, center, angle_deg, BriefPattern().data(), kBriefBits, out);
}

}  // namespace dynorb
