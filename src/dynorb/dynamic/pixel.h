// The image pixel nearest to a sub-pixel point (rounded, clamped to the image): where the
// dynamic filters look a point up in a mask or a depth map.
#pragma once

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

namespace dynorb {

inline cv::Point NearestPixel(const cv::Point2f& p, const cv::Size& size) {
  return {std::clamp(static_cast<int>(std::lround(p.x)), 0, size.width - 1),
          std::clamp(static_cast<int>(std::lround(p.y)), 0, size.height - 1)};
}

}  // namespace dynorb
