// Helpers shared by the FAST mode's tests: the camera of the constructed scenes and the error of
// an ego-motion estimate.
#pragma once

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/dynamic/motion_ego.h"

namespace dynorb {

// 640x480, f = 525 px, principal point at the image centre.
inline PinholeCamera FastTestCamera() {
  PinholeCamera c;
  c.fx = c.fy = 525.0;
  c.cx = 319.5;
  c.cy = 239.5;
  c.width = 640;
  c.height = 480;
  return c;
}

// Rotation angle (rad) plus translation error (m) of an ego-motion estimate against the truth.
inline double MotionError(const EgoMotionResult& r, const Rigid3d& truth) {
  return RotationAngleRad(r.prev_from_cur.rotation * truth.rotation.conjugate()) +
         (r.prev_from_cur.translation - truth.translation).norm();
}

}  // namespace dynorb
