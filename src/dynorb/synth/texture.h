// Texture: a BGR image with its mip pyramid, optionally a sprite (alpha + body bulge).
// The pyramid is built with cv::pyrDown, so texel coordinates scale exactly by 1/2 per level
// (level-L coordinate = level-0 coordinate / 2^L). Immutable after construction; safe to share
// between rendering threads.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace dynorb::synth {

struct Texture {
  std::vector<cv::Mat> levels;  // CV_8UC3 BGR; levels[0] is full resolution
  cv::Mat alpha_bulge;          // sprites only: CV_32FC2 (alpha in [0,1], bulge / sprite width)
  float max_bulge = 0.f;        // sprites only: the largest bulge in alpha_bulge (see MakeSpriteFromMaps)

  bool IsSprite() const { return !alpha_bulge.empty(); }
  int width() const { return levels.empty() ? 0 : levels[0].cols; }
  int height() const { return levels.empty() ? 0 : levels[0].rows; }
};

// Builds the pyramid (down to ~16 texels) of an opaque CV_8UC3 image.
Texture MakeTexture(const cv::Mat& bgr);

// A sprite from a CV_8UC4 BGRA cut-out. The bulge map gives, per texel with alpha > 0.5, how far
// the body surface sticks out of the billboard towards the viewer, as a fraction of the sprite
// width: an elliptical cross-section across each horizontal run of the silhouette with a
// depth/width ratio of `depth_ratio`.
Texture MakeSprite(const cv::Mat& bgra, double depth_ratio = 0.55);

// A sprite from its colour (CV_8UC3) and its alpha/bulge map (CV_32FC2, same size); sets max_bulge.
Texture MakeSpriteFromMaps(const cv::Mat& bgr, const cv::Mat& alpha_bulge);

}  // namespace dynorb::synth
