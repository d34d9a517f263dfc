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
  // Replace the colours of partly transparent texels (feathered cut-out edges still carry the
  // photo's background, e.g. grass) by those of nearby fully opaque texels, so neither the
  // alpha-tested silhouette nor bilinear filtering shows a coloured halo.
  cv::Mat alpha;
  cv::extractChannel(bgra, alpha, 3);
  cv::Mat opaque = alpha > 235;
  cv::Mat filled = bgr.clone();
  filled.setTo(cv::Scalar(0, 0, 0), ~opaque);
  cv::Mat weight;
  opaque.convertTo(weight, CV_32F, 1.0 / 255.0);
  cv::Mat colour_sum, weight_sum;
  filled.convertTo(colour_sum, CV_32FC3);
  for (int i = 0; i < 4; ++i) {  // grow the opaque colours outwards by ~4 texels
    cv::Mat blurred_colour, blurred_weight;
    cv::blur(colour_sum, blurred_colour, cv::Size(3, 3));
    cv::blur(weight, blurred_weight, cv::Size(3, 3));
    colour_sum = blurred_colour;
    weight = blurred_weight;
    weight_sum = weight;
  }
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x)
      if (!opaque.at<uchar>(y, x) && weight_sum.at<float>(y, x) > 1e-4f)
        bgr.at<cv::Vec3b>(y, x) =
            cv::Vec3b(colour_sum.at<cv::Vec3f>(y, x) / weight_sum.at<float>(y, x));
  cv::Mat smooth;
  cv::blur(bgr, smooth, cv::Size(3, 3));
  bgr.copyTo(smooth, opaque);
  const int w = bgra.cols;
  cv::Mat alpha_bulge(bgra.size(), CV_32FC2);
  for (int y = 0; y < bgra.rows; ++y) {
    const uchar* a = alpha.ptr<uchar>(y);
    auto* out = alpha_bulge.ptr<cv::Vec2f>(y);
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
  return MakeSpriteFromMaps(smooth, alpha_bulge);
}

Texture MakeSpriteFromMaps(const cv::Mat& bgr, const cv::Mat& alpha_bulge) {
  CV_Assert(bgr.type() == CV_8UC3 && alpha_bulge.type() == CV_32FC2 && bgr.size() == alpha_bulge.size());
  Texture texture = MakeTexture(bgr);
  texture.alpha_bulge = alpha_bulge;
  cv::Mat bulge;
  cv::extractChannel(alpha_bulge, bulge, 1);
  double max_bulge = 0.0;
  cv::minMaxLoc(bulge, nullptr, &max_bulge);
  texture.max_bulge = static_cast<float>(std::max(0.0, max_bulge));
  return texture;
}

}  // namespace dynorb::synth
