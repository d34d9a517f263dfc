#include "dynorb/map/frame_features.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>

namespace dynorb {

FrameFeatures::FrameFeatures(const OrbFeatures& orb, const cv::Mat& depth_m, const RgbdSensor& sensor,
                             const ScaleLevels& levels)
    : keypoints_(orb.keypoints), descriptors_(orb.descriptors), levels_(levels) {
  const int n = static_cast<int>(keypoints_.size());
  depth_m_.assign(n, 0.0f);
  nearby_min_depth_m_.assign(n, 0.0f);
  // Depth is sampled at the extracted (distorted) position, where the depth image is registered.
  const int r = kNearbyDepthRadiusPx;
  for (int i = 0; i < n && !depth_m.empty(); ++i) {
    const int x = static_cast<int>(std::lround(keypoints_[i].pt.x));
    const int y = static_cast<int>(std::lround(keypoints_[i].pt.y));
    if (x < 0 || y < 0 || x >= depth_m.cols || y >= depth_m.rows) continue;
    const float d = depth_m.at<float>(y, x);
    if (d > 0.0f && std::isfinite(d)) depth_m_[i] = d;
    // Branch-free minimum over the window (vectorises): no measurement (0, NaN, +inf) counts as +inf.
    constexpr float kNone = std::numeric_limits<float>::infinity();
    float nearest = kNone;
    const int x0 = std::max(0, x - r), x1 = std::min(depth_m.cols - 1, x + r);
    for (int yy = std::max(0, y - r); yy <= std::min(depth_m.rows - 1, y + r); ++yy) {
      const float* row = depth_m.ptr<float>(yy);
      for (int xx = x0; xx <= x1; ++xx) {
        const float v = row[xx];
        nearest = std::min(nearest, v > 0.0f ? v : kNone);
      }
    }
    nearby_min_depth_m_[i] = nearest < kNone ? nearest : 0.0f;
  }
  if (!depth_m.empty()) {  // Every 4th pixel of every 4th row is plenty for a percentile.
    std::vector<float> samples;
    samples.reserve(static_cast<size_t>(depth_m.rows / 4 + 1) * (depth_m.cols / 4 + 1));
    for (int y = 0; y < depth_m.rows; y += 4) {
      const float* row = depth_m.ptr<float>(y);
      for (int x = 0; x < depth_m.cols; x += 4) {
        if (row[x] > 0.0f && std::isfinite(row[x])) samples.push_back(row[x]);
      }
    }
    if (!samples.empty()) {
      auto nth = samples.begin() + static_cast<std::ptrdiff_t>(0.95 * static_cast<double>(samples.size() - 1));
      std::nth_element(samples.begin(), nth, samples.end());
      far_depth_m_ = *nth;
    }
  }
  Finish(sensor);
}

FrameFeatures::FrameFeatures(const OrbFeatures& orb, const std::vector<float>& keypoint_depth_m,
                             const RgbdSensor& sensor, const ScaleLevels& levels)
    : keypoints_(orb.keypoints), descriptors_(orb.descriptors), levels_(levels) {
  depth_m_.assign(keypoints_.size(), 0.0f);
  nearby_min_depth_m_.assign(keypoints_.size(), 0.0f);  // Unknown: no depth image.
  for (size_t i = 0; i < keypoints_.size() && i < keypoint_depth_m.size(); ++i) {
    if (keypoint_depth_m[i] > 0.0f && std::isfinite(keypoint_depth_m[i])) depth_m_[i] = keypoint_depth_m[i];
  }
  Finish(sensor);
}

void FrameFeatures::Finish(const RgbdSensor& sensor) {
  const int n = static_cast<int>(keypoints_.size());
  u_right_.assign(n, -1.0f);
  disparity_information_ = sensor.disparity_sigma_px > 0.0
                               ? 1.0 / (sensor.disparity_sigma_px * sensor.disparity_sigma_px)
                               : 0.0;
  if (sensor.camera.HasDistortion() && n > 0) {
    std::vector<cv::Point2f> in(n), out;
    for (int i = 0; i < n; ++i) in[i] = keypoints_[i].pt;
    cv::Mat k = (cv::Mat_<double>(3, 3) << sensor.camera.fx, 0, sensor.camera.cx, 0, sensor.camera.fy,
                 sensor.camera.cy, 0, 0, 1);
    cv::Mat dist = (cv::Mat_<double>(1, 5) << sensor.camera.k1, sensor.camera.k2, sensor.camera.p1,
                    sensor.camera.p2, sensor.camera.k3);
    cv::undistortPoints(in, out, k, dist, cv::noArray(), k);
    for (int i = 0; i < n; ++i) keypoints_[i].pt = out[i];
  }
  for (int i = 0; i < n; ++i) {
    if (depth_m_[i] > 0.0f) u_right_[i] = keypoints_[i].pt.x - static_cast<float>(sensor.bf / depth_m_[i]);
  }
  grid_.emplace(keypoints_, cv::Size(sensor.camera.width, sensor.camera.height), 16.0f);
}

KeypointObservation FrameFeatures::Observation(int i) const {
  KeypointObservation obs;
  obs.uv = Eigen::Vector2d(keypoints_[i].pt.x, keypoints_[i].pt.y);
  obs.u_right = u_right_[i];
  obs.information = levels_.inv_sigma2[keypoints_[i].octave];
  obs.disparity_information = disparity_information_;
  return obs;
}

Eigen::Vector3d FrameFeatures::PointInCam(int i, const PinholeCamera& camera) const {
  return camera.Unproject(Eigen::Vector2d(keypoints_[i].pt.x, keypoints_[i].pt.y), depth_m_[i]);
}

std::vector<int> FrameFeatures::FeaturesInArea(double x, double y, double radius_px, int min_level,
                                               int max_level) const {
  if (!grid_) return {};
  return grid_->FindInRadius(static_cast<float>(x), static_cast<float>(y), static_cast<float>(radius_px),
                             min_level, max_level);
}

}  // namespace dynorb
