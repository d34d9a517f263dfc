// KeypointObservation: one keypoint measurement as the optimisers use it — pixel position, the
// virtual right coordinate u_r = u - bf / depth for RGB-D (ORB-SLAM2's stereo form; < 0 when the
// keypoint has no depth) and the information 1 / sigma^2 of its pyramid level (px^-2).
#pragma once

#include <Eigen/Core>

namespace dynorb {

struct KeypointObservation {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  double u_right = -1.0;     // < 0: monocular observation (no valid depth).
  double information = 1.0;  // 1 / sigma^2 in px^-2.
  bool IsStereo() const { return u_right >= 0.0; }
};

}  // namespace dynorb
