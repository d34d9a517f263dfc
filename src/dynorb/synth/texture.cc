#include "dynorb/synth/texture.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace dynorb::synth {

Texture MakeTexture(const cv::Mat& bgr) {
  CV_Assert(bgr.type() == CV_8UC3 && !bgr.empty());
  Texture texture;
  texture.levels.push_back(bgr.clone());
  while (texture.levels.back().cols > 16 && texture.levels.back().rows > 16) {
    cv::Mat next;
    cv::pyrDown(texture.levels.back(), next);
    texture.levels.push_back(next);
  }
  return texture;
}

Texture MakeSprite(const cv::Mat& bgra, double depth_ratio) {
  CV_Assert(bgra.type() == CV_8UC4 && !bgra.empty());
  cv::Mat bgr;
  cv::cvtColor(bgra, bgr, cv::COLOR_BGRA2BGR);
  // Bleed colours of opaque texels into transparent ones so bilinear filtering at the
  // silhouette does not pull in the (arbitrary) colour of transparent texels.
  cv::Mat alpha;
  cv::extractChannel(bgra, alpha, 3);
  cv::Mat opaque = alpha > 127;
  cv::Mat dilated;
  cv::dilate(bgr, dilated, cv::Mat(), cv::Point(-1, -1), 2);
  dilated.copyTo(bgr, ~opaque);
  cv::Mat smooth;
  cv::blur(bgr, smooth, cv::Size(3, 3));
  bgr.copyTo(smooth, opaque);
  Texture texture = MakeTexture(smooth);

  const int w = bgra.cols;
  texture.alpha_bulge.create(bgra.size(), CV_32FC2);
  for (int y = 0; y < bgra.rows; ++y) {
    const uchar* a = alpha.ptr<uchar>(y);
    auto* out = texture.alpha_bulge.ptr<cv::Vec2f>(y);
    for (int x = 0; x < w; ++x) out[x] = cv::Vec2f(a[x] / 255.0f, 0.0f);
    // Elliptical cross-section over each run of opaque texels in this row.
    int x = 0;
    while (x < w) {
      if (a[x] <= 127) {
        ++x;
        continue;
      }
      int end = x;
      while (end < w && a[end] > 127) ++end;
      const double half = 0.5 * (end - x);
      const double centre = 0.5 * (x + end) - 0.5;
      const double depth = std::min(depth_ratio * half, 0.2 * w);  // thin limbs stay thin
      for (int i = x; i < end; ++i) {
        const double r = (i - centre) / (half + 0.5);
        out[i][1] = static_cast<float>(depth * std::sqrt(std::max(0.0, 1.0 - r * r)) / w);
      }
      x = end;
    }
  }
  return texture;
}

}  // namespace dynorb::synth
