// Test-only: an exact feature-level world for tracking/mapping tests. Points lie on the walls,
// floor and ceiling of a 6 x 5 x 3 m room; each has a fixed random descriptor, pyramid level and
// keypoint angle. A frame at a known pose observes the visible points with pixel noise, depth
// noise and a few flipped descriptor bits — what an ideal ORB extractor + Kinect would give.
#pragma once

#include <algorithm>
#include <memory>
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "dynorb/map/frame_features.h"
#include "dynorb/tracking/frame.h"

namespace dynorb::testing {

class FeatureWorld {
 public:
  explicit FeatureWorld(uint64_t seed, int num_points = 6000) : rng_(seed) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < num_points; ++i) {
      Eigen::Vector3d p;
      const int face = i % 5;  // 0..3 walls, 4 floor/ceiling
      const double a = u(rng_), b = u(rng_);
      switch (face) {
        case 0: p = {-3.0 + 6.0 * a, -1.5 + 3.0 * b, 3.0}; break;   // front wall (z = 3)
        case 1: p = {-3.0, -1.5 + 3.0 * b, -2.0 + 5.0 * a}; break;  // left wall
        case 2: p = {3.0, -1.5 + 3.0 * b, -2.0 + 5.0 * a}; break;   // right wall
        case 3: p = {-3.0 + 6.0 * a, -1.5 + 3.0 * b, -2.0}; break;  // back wall
        default: p = {-3.0 + 6.0 * a, b < 0.5 ? 1.5 : -1.5, -2.0 + 5.0 * u(rng_)}; break;
      }
      points_.push_back(p);
      std::array<uint8_t, 32> d;
      for (auto& byte : d) byte = static_cast<uint8_t>(rng_());
      descriptors_.push_back(d);
      levels_.push_back(static_cast<int>(u(rng_) * 3.0));
      angles_.push_back(static_cast<float>(u(rng_) * 360.0));
    }
    sensor_.camera = TumFreiburg3Camera();
    sensor_.bf = 40.0;
    sensor_.th_depth_m = 40.0 * 40.0 / 535.4;
  }

  const RgbdSensor& sensor() const { return sensor_; }
  const std::vector<Eigen::Vector3d>& points() const { return points_; }

  // A smooth hand-held path looking roughly at the front wall (+z).
  static Rigid3d WorldFromCam(int frame) {
    const double t = frame / 30.0;
    const Eigen::Vector3d position(0.4 * std::sin(0.9 * t), 0.15 * std::sin(1.7 * t), 0.3 * std::sin(0.6 * t));
    const Eigen::Quaterniond rotation = Eigen::AngleAxisd(0.6 * std::sin(0.8 * t), Eigen::Vector3d::UnitY()) *
                                        Eigen::AngleAxisd(0.05 * std::sin(1.3 * t), Eigen::Vector3d::UnitX()) *
                                        Eigen::AngleAxisd(0.04 * std::sin(0.7 * t), Eigen::Vector3d::UnitZ());
    return Rigid3d(rotation, position);
  }

  // The depth image (CV_32F metres along the optical axis) of the empty room from this pose: every
  // pixel's ray meets the nearest wall, floor or ceiling.
  cv::Mat RenderDepth(const Rigid3d& world_from_cam) const {
    const PinholeCamera& c = sensor_.camera;
    cv::Mat depth(c.height, c.width, CV_32F);
    const Eigen::Vector3d lo(-3.0, -1.5, -2.0), hi(3.0, 1.5, 3.0),
        origin = world_from_cam.translation;
    for (int v = 0; v < c.height; ++v) {
      for (int u = 0; u < c.width; ++u) {
        // The ray of depth 1: its length along the optical axis is 1, so the hit's t is the depth.
        const Eigen::Vector3d ray =
            world_from_cam.rotation * Eigen::Vector3d((u - c.cx) / c.fx, (v - c.cy) / c.fy, 1.0);
        double t = 1e9;
        for (int a = 0; a < 3; ++a) {
          if (ray[a] > 1e-12) t = std::min(t, (hi[a] - origin[a]) / ray[a]);
          if (ray[a] < -1e-12) t = std::min(t, (lo[a] - origin[a]) / ray[a]);
        }
        depth.at<float>(v, u) = static_cast<float>(t);
      }
    }
    return depth;
  }

  // `point_ids` (optional) receives the world point index of each keypoint.
  std::shared_ptr<const FrameFeatures> Observe(const Rigid3d& world_from_cam, uint64_t frame_seed,
                                               double pixel_sigma = 0.5, std::vector<int>* point_ids = nullptr) const {
    std::mt19937_64 rng(frame_seed);
    std::normal_distribution<double> n(0.0, 1.0);
    std::uniform_int_distribution<int> bit(0, 255), flips(0, 6);
    const Rigid3d cam_from_world = world_from_cam.Inverse();
    OrbFeatures orb;
    std::vector<float> depths;
    std::vector<std::array<uint8_t, 32>> rows;
    const ScaleLevels levels(8, 1.2);
    if (point_ids != nullptr) point_ids->clear();
    for (size_t i = 0; i < points_.size(); ++i) {
      const Eigen::Vector3d p = cam_from_world * points_[i];
      if (p.z() < 0.3) continue;
      const Eigen::Vector2d uv = sensor_.camera.Project(p);
      if (uv.x() < 20 || uv.y() < 20 || uv.x() > 619 || uv.y() > 459) continue;
      const double sigma = pixel_sigma * levels.scale[levels_[i]];
      cv::KeyPoint kp(cv::Point2f(static_cast<float>(uv.x() + sigma * n(rng)), static_cast<float>(uv.y() + sigma * n(rng))),
                      31.0f, angles_[i], 1.0f, levels_[i]);
      orb.keypoints.push_back(kp);
      if (point_ids != nullptr) point_ids->push_back(static_cast<int>(i));
      depths.push_back(static_cast<float>(p.z() * (1.0 + 0.002 * p.z() * n(rng))));
      std::array<uint8_t, 32> d = descriptors_[i];
      const int k = flips(rng);
      for (int f = 0; f < k; ++f) {
        const int b = bit(rng);
        d[b / 8] ^= static_cast<uint8_t>(1u << (b % 8));
      }
      rows.push_back(d);
    }
    orb.descriptors = cv::Mat(static_cast<int>(rows.size()), 32, CV_8U);
    for (size_t r = 0; r < rows.size(); ++r) std::memcpy(orb.descriptors.ptr(static_cast<int>(r)), rows[r].data(), 32);
    return std::make_shared<const FrameFeatures>(orb, depths, sensor_, levels);
  }

 private:
  std::mt19937_64 rng_;
  RgbdSensor sensor_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<std::array<uint8_t, 32>> descriptors_;
  std::vector<int> levels_;
  std::vector<float> angles_;
};

// Pose error of an estimate expressed in the first camera's frame (the SLAM world).
inline Rigid3d TruthInFirstCamera(int frame) {
  return FeatureWorld::WorldFromCam(frame).Inverse() * FeatureWorld::WorldFromCam(0);  // cam_from_firstcam
}

}  // namespace dynorb::testing
