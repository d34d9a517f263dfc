// The 256 point-pair comparisons of dynorb's steered BRIEF descriptor, and the candidate
// generator they were learned from.
//
// The pattern is dynorb's own: no table was copied. It was selected by dynorb's implementation of
// the rBRIEF learning procedure (Rublee et al., "ORB: an efficient alternative to SIFT or SURF",
// ICCV 2011, §4.3; see brief_learning.h) from a deterministic pool of candidate pairs
// (GenerateBriefCandidates below) on keypoints of a fixed list of training images (docs/features.md
// lists them; the DISABLED_ test in brief_learning_test.cc regenerates the table). Learned tests
// are balanced (bit mean near 0.5) and mutually decorrelated after steering, which a raw random
// pattern is not (steered BRIEF loses variance — ORB paper §4.1).
//
// Consequence (docs/features.md): descriptors are NOT bit-compatible with ORB-SLAM2 / OpenCV ORB
// (which share the learned pattern of the ORB paper), so vocabularies trained on those (ORBvoc.txt)
// cannot be used; place recognition must train on dynorb descriptors. Changing the table
// invalidates every stored descriptor and vocabulary — a test pins its checksum.
//
// Thread-safe: read-only data.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace dynorb {

struct BriefPair {
  int8_t x1, y1, x2, y2;  // offsets from the keypoint in level pixels (x right, y down)
};

constexpr int kBriefBits = 256;
constexpr int kBriefBytes = kBriefBits / 8;
constexpr int kBriefMaxRadius = 15;  // every pattern point satisfies x² + y² ≤ 15²
constexpr uint64_t kBriefCandidateSeed = 0x0D1D0B5EEDULL;

// Bit i of the descriptor (byte i / 8, bit i % 8, LSB first) is 1 iff I(p1) < I(p2), where the
// points are rotated by the keypoint angle and I is the Gaussian-blurred pyramid level.
const std::array<BriefPair, kBriefBits>& BriefPattern();

// Candidate pool of the learning: `count` distinct pairs (p1 ≠ p2, no repeated pair in either
// order) inside the disc of radius kBriefMaxRadius, alternating between two families:
//  - even indices: both points i.i.d. ≈ N(0, (31/5)²) — BRIEF's "G II" sampling (Calonder et al.,
//    ECCV 2010), approximated by the Irwin–Hall sum of 12 uniforms;
//  - odd indices: both points uniform in the disc (the ORB paper's candidates span the whole
//  patch).
// Randomness is SplitMix64 from `seed` in integer arithmetic: identical on every platform.
std::vector<BriefPair> GenerateBriefCandidates(uint64_t seed, int count,
                                               int max_radius = kBriefMaxRadius);

}  // namespace dynorb
