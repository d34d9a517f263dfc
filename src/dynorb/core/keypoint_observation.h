// KeypointObservation: one keypoint measurement as the optimisers use it — pixel position, the
// virtual right coordinate u_r = u - bf / depth for RGB-D (ORB-SLAM2's stereo form; < 0 when the
// keypoint has no depth), the information 1 / sigma^2 of its pyramid level (px^-2) and, when
// set, the information of the depth measured as a disparity d = u - u_r = bf / depth.
#pragma once

#include <Eigen/Core>

namespace dynorb {

// The default depth noise as a disparity standard deviation (px, units of bf): twice a Kinect v1's
// (~0.07 px at 1-4 m), for the depth sampled a keypoint's noise away from the point. Used by the
// config key DepthDisparitySigma and RgbdSensor::disparity_sigma_px (docs/slam_core.md).
inline constexpr double kDefaultDisparitySigmaPx = 0.15;

struct KeypointObservation {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  double u_right = -1.0;     // < 0: monocular observation (no valid depth).
  double information = 1.0;  // 1 / sigma^2 in px^-2.
  // 1 / sigma_d^2 (px^-2) of the disparity d = u - u_r, the depth sensor's own noise. 0: the third
  // residual is ORB-SLAM2's u_r - predicted u_r weighted by `information` (which also carries the
  // keypoint's pixel noise and rates a Kinect's depth ~10x too noisy at 1-4 m).
  double disparity_information = 0.0;
  bool IsStereo() const { return u_right >= 0.0; }
};

}  // namespace dynorb
