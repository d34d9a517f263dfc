// Box -> mask refinement with depth (the weakness of box masks named in the report: the
// background inside a person's box). Inside the box, the object is the depth cluster around a
// reference depth (the mode of the central part of the box, or a hint carried from a previous
// frame); pixels of that cluster form the mask, which is closed and dilated. Background pixels
// inside the box (a far wall behind a person) stay static. Pure function of its inputs.
#pragma once

#include <opencv2/core.hpp>

namespace dynorb {

struct DepthRefineOptions {
  bool enabled = true;              // false: the whole box is the mask
  double band_m = 0.4;              // |depth - reference| below band + band_per_m * reference
  double band_per_m = 0.05;         // depth-proportional part of the band (noise grows with depth)
  int dilation_px = 8;              // dilation of the mask (covers edges and depth shadows)
  double min_valid_fraction = 0.1;  // fewer valid depths in the box -> whole box (no evidence)
  void Validate() const;
};

struct RefinedMask {
  float depth_m = 0.f;  // reference (foreground) depth; 0 when the box was used as is
  bool refined = false;
};

// ORs the object's mask into `mask` (CV_8U, depth size, 255 = dynamic). `depth_hint_m` > 0 picks
// the cluster nearest that depth instead of the central mode (mask propagation).
RefinedMask AddRefinedBoxMask(const cv::Rect2f& box, const cv::Mat& depth_m,
                              const DepthRefineOptions& options, float depth_hint_m, cv::Mat* mask);

}  // namespace dynorb
