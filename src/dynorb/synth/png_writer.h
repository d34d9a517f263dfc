// Fast PNG encoding for the sequence writer. libpng's adaptive row filtering dominates the cost
// of writing noisy 640x480 frames through cv::imencode; this encoder uses one fixed filter (Sub)
// and zlib's fast run-length strategy, which is ~3x faster at a similar size. Output is a
// standard PNG (8-bit RGB from BGR, 8-bit grey, or 16-bit grey) readable by any decoder.
// Pure function; thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace dynorb::synth {

// image: CV_8UC3 (BGR), CV_8UC1 or CV_16UC1. Returns the PNG file's bytes.
std::string EncodePng(const cv::Mat& image);

}  // namespace dynorb::synth
