// Kinect-like sensor effects applied to rendered frames.
//
// Depth (Kinect v1 / TUM fr3): axial noise sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2 m (Nguyen,
// Izadi, Lovell, "Modeling Kinect sensor noise", 3DIMPVT 2012), spatially correlated over a few
// pixels (block matching); disparity quantised to 1/8 px with focal * baseline = 580 * 0.075;
// no depth beyond `max_depth_m` (ragged), in ragged bands along depth discontinuities, in the
// projector's shadow left of foreground edges, in a band at the right border, and at a few random
// speckles; stored as uint16 with factor 5000.
// RGB: slight optical softness, motion blur along the image motion (exposure ~ 40 % of the frame
// interval), slight vignetting, an auto-exposure gain, and shot + read noise. All random draws come
// from a generator seeded per frame: results depend only on the inputs. Pure functions;
// thread-safe.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

namespace dynorb::synth {

struct SensorOptions {
  bool noise = true;         // false: exact depth (quantised to 1/5000 m), clean RGB
  double max_depth_m = 4.5;  // farther surfaces have no depth (also without noise)
  double depth_factor = 5000.0;
  double exposure_fraction = 0.4;  // motion blur length = this * image motion per frame
};

// depth_m: CV_32F (0 = none). Returns CV_16U in units of 1 / depth_factor m.
cv::Mat DepthToSensor(const cv::Mat& depth_m, const SensorOptions& options, uint64_t seed);

// In-place on a CV_8UC3 image. motion_px: image motion per frame (blur direction and length);
// gain: auto-exposure multiplier.
void ApplyRgbEffects(cv::Mat* rgb, const cv::Point2d& motion_px, double gain,
                     const SensorOptions& options, uint64_t seed);

}  // namespace dynorb::synth
