// Per-keypoint ORB building blocks: intensity-centroid orientation and steered BRIEF.
//
// Rublee et al., "ORB: an efficient alternative to SIFT or SURF", ICCV 2011, §3.2 and §4.
// Both work in the pixel grid of one pyramid level; `center` is an integer pixel at least
// kEdgeThreshold pixels inside the image (checked with CHECK-style asserts in debug builds only).
// Pure functions; thread-safe.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "dynorb/features/brief_pattern.h"

namespace dynorb {

// Orientation in degrees, [0, 360), of the intensity centroid of the disc u² + v² ≤ 240 (radius
// ≈ kHalfPatchSize) around `center` of the (unblurred) level image: atan2(m01, m10) with
// m_pq = Σ u^p v^q I(center + (u, v)), x right, y down — the cv::KeyPoint::angle convention.
float IntensityCentroidAngleDeg(const cv::Mat& level, cv::Point center);

// 256-bit steered BRIEF of the Gaussian-blurred level image (7×7, σ = 2) at `center`: the pattern
// of brief_pattern.h rotated by `angle_deg` (p' = R(angle)·p, rounded to the nearest pixel).
// Writes kBriefBytes bytes to `out`.
void ComputeSteeredBrief(const cv::Mat& blurred_level, cv::Point center, float angle_deg,
                         uint8_t* out);

// The same for an arbitrary list of n pairs (points within kBriefMaxRadius): bit i of the packed
// output (byte i / 8, LSB first) is the test of pairs[i]. Writes (n + 7) / 8 bytes.
void ComputeSteeredTests(const cv::Mat& blurred_level, cv::Point center, float angle_deg,
                         const BriefPair* pairs, int n, uint8_t* out);

}  // namespace dynorb
