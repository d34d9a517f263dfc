// The 16 pixels of FAST's Bresenham circle of radius 3 (OpenCV's pattern, clockwise from the
// bottom), and its points around a keypoint at its pyramid level in full-resolution pixels.
// A FAST corner is decided by these pixels only: they are its support.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/core.hpp>

namespace dynorb {

constexpr int kFastCircle[16][2] = {{0, 3},  {1, 3},   {2, 2},   {3, 1},  {3, 0},  {3, -1}, {2, -2}, {1, -3},
                                    {0, -3}, {-1, -3}, {-2, -2}, {-3, -1}, {-3, 0}, {-3, 1}, {-2, 2}, {-1, 3}};

// The circle of keypoint `kp` (full-resolution `pt`, `octave` = level) scaled by
// scale_factor^octave, rounded to full-resolution pixels (may lie outside the image).
inline std::array<cv::Point, 16> FastCirclePixels(const cv::KeyPoint& kp, double scale_factor) {
  const double s = std::pow(scale_factor, std::max(0, kp.octave));
  std::array<cv::Point, 16> pixels;
  for (int k = 0; k < 16; ++k) {
    pixels[k] = cv::Point(static_cast<int>(std::lround(kp.pt.x + kFastCircle[k][0] * s)),
                          static_cast<int>(std::lround(kp.pt.y + kFastCircle[k][1] * s)));
  }
  return pixels;
}

}  // namespace dynorb
