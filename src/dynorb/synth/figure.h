// Procedural articulated human figures, used when no real cut-outs are available: a textured
// head, torso, arms and legs (plaid shirt, denim trousers) drawn into RGBA sprites, one per gait
// phase, with cylindrical shading. Deterministic for a given seed.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace dynorb::synth {

// `phases` BGRA sprites (CV_8UC4) of one person over a walking cycle; sprite height `height_px`.
std::vector<cv::Mat> MakeFigureSprites(uint64_t seed, int phases, int height_px = 640);

}  // namespace dynorb::synth
