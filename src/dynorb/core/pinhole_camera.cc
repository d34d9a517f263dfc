#include "dynorb/core/pinhole_camera.h"

namespace dynorb {
namespace {
PinholeCamera Make(double fx, double fy, double cx, double cy, double k1, double k2, double p1, double p2,
                   double k3) {
  PinholeCamera c;
  c.fx = fx; c.fy = fy; c.cx = cx; c.cy = cy;
  c.k1 = k1; c.k2 = k2; c.p1 = p1; c.p2 = p2; c.k3 = k3;
  c.width = 640; c.height = 480;
  return c;
}
}  // namespace

PinholeCamera TumFreiburg1Camera() {
  return Make(517.306408, 516.469215, 318.643040, 255.313989, 0.262383, -0.953104, -0.005358, 0.002628,
              1.163314);
}
PinholeCamera TumFreiburg2Camera() {
  return Make(520.908620, 521.007327, 325.141442, 249.701764, 0.231222, -0.784899, -0.003257, -0.000105,
              0.917205);
}
// fr3 images are already undistorted by the dataset authors, hence zero distortion.
PinholeCamera TumFreiburg3Camera() { return Make(535.4, 539.2, 320.1, 247.6, 0.0, 0.0, 0.0, 0.0, 0.0); }

}  // namespace dynorb
