// Limits of the ORB extractor's settings, shared by the config (io/) and the extractor (features/).
#pragma once

namespace dynorb {

// More features than this per image is no SLAM setting (and overflowed the per-level budgets).
inline constexpr int kMaxOrbFeatures = 1000000;
// Closer to 1, the levels of a 640 x 480 pyramid come out the same size (ORB-SLAM2 uses 1.2).
inline constexpr double kMinOrbScaleFactor = 1.05;

}  // namespace dynorb
