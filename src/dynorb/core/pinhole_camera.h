// PinholeCamera: intrinsics (+ Brown-Conrady distortion coefficients as in OpenCV / ORB-SLAM2)
// of a camera with `width` x `height` pixels. Pixel (u, v): u to the right, v down; the centre
// of the top-left pixel is (0, 0). Camera frame: x right, y down, z forward (optical axis).
// Value type, thread-compatible.
#pragma once

#include <Eigen/Core>

namespace dynorb {

struct PinholeCamera {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  double k1 = 0.0, k2 = 0.0, p1 = 0.0, p2 = 0.0, k3 = 0.0;  // OpenCV distortion order k1 k2 p1 p2 k3
  int width = 0, height = 0;

  bool HasDistortion() const { return k1 != 0.0 || k2 != 0.0 || p1 != 0.0 || p2 != 0.0 || k3 != 0.0; }
  Eigen::Matrix3d K() const {
    Eigen::Matrix3d k;
    k << fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0;
    return k;
  }
  // Ideal (undistorted) projection of a point in the camera frame; z must be > 0.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const {
    return {fx * point_in_cam.x() / point_in_cam.z() + cx, fy * point_in_cam.y() / point_in_cam.z() + cy};
  }
  // Back-projects an (undistorted) pixel with depth along the optical axis (metres).
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel, double depth_m) const {
    return {(pixel.x() - cx) / fx * depth_m, (pixel.y() - cy) / fy * depth_m, depth_m};
  }
  bool InImage(const Eigen::Vector2d& pixel) const {
    return pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() <= width - 1.0 && pixel.y() <= height - 1.0;
  }
};

// The official TUM RGB-D intrinsics (from the TUM benchmark's camera calibration page).
PinholeCamera TumFreiburg1Camera();
PinholeCamera TumFreiburg2Camera();
PinholeCamera TumFreiburg3Camera();

}  // namespace dynorb
