// FrameFeatures: the immutable measurements of one RGB-D frame that tracking, mapping and
// relocalisation use — undistorted keypoints (full-resolution pixels, octave = pyramid level),
// their 256-bit descriptors, the depth of each keypoint and its virtual right coordinate
// u_r = u - bf / depth (ORB-SLAM2's stereo form of RGB-D), and a grid for radius queries.
// Built once per frame (BuildFrameFeatures), then shared read-only by a Frame and, if it becomes
// one, its Keyframe (std::shared_ptr<const FrameFeatures>). Thread-safe after construction.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "dynorb/core/keypoint_observation.h"
#include "dynorb/core/pinhole_camera.h"
#include "dynorb/features/image_pyramid.h"
#include "dynorb/features/orb_extractor.h"
#include "dynorb/features/orb_matcher.h"


namespace dynorb {

struct RgbdSensor {
  PinholeCamera camera;     // Intrinsics of the RGB image (depth registered to it).
  double bf = 40.0;         // Virtual stereo baseline times fx (ORB-SLAM2 Camera.bf), px*m.
  double th_depth_m = 3.0;  // Close/far threshold in metres (ORB-SLAM2: ThDepth * bf / fx).
  // Depth noise as a disparity standard deviation (px, in units of bf): the weight of the depth in
  // the RGB-D residual (reprojection_cost.h). 0: ORB-SLAM2's u_r residual with the keypoint's
  // sigma.
  double disparity_sigma_px = kDefaultDisparitySigmaPx;
};

class FrameFeatures {
 public:
  FrameFeatures() = default;
  // keypoints as extracted (distorted pixels); depth_m: CV_32F metres registered to the image
  // (0 = no depth). Undistorts the keypoints and samples depth at the extracted position.
  FrameFeatures(const OrbFeatures& orb, const cv::Mat& depth_m, const RgbdSensor& sensor,
                const ScaleLevels& levels);
  // Same with one depth per keypoint (metres, <= 0: none), e.g. from another depth source.
  FrameFeatures(const OrbFeatures& orb, const std::vector<float>& keypoint_depth_m, const RgbdSensor& sensor,
                const ScaleLevels& levels);

  int size() const { return static_cast<int>(keypoints_.size()); }
  const cv::KeyPoint& keypoint(int i) const { return keypoints_[i]; }
  const std::vector<cv::KeyPoint>& keypoints() const { return keypoints_; }
  const uint8_t* descriptor(int i) const { return descriptors_.ptr<uint8_t>(i); }
  const cv::Mat& descriptors() const { return descriptors_; }
  float depth(int i) const { return depth_m_[i]; }
  float u_right(int i) const { return u_right_[i]; }
  bool HasDepth(int i) const { return depth_m_[i] > 0.0f; }
  bool IsClose(int i, double th_depth_m) const { return HasDepth(i) && depth_m_[i] < th_depth_m; }
  // Smallest valid depth in the square of half-side kNearbyDepthRadiusPx around keypoint i's
  // extracted position (metres; 0 = none measured or no depth image). A point seen at the
  // keypoint cannot lie much nearer than every surface the depth camera measured around it (it
  // would occlude them): this bounds new landmarks at keypoints without depth.
  float nearby_min_depth(int i) const { return nearby_min_depth_m_[i]; }
  static constexpr int kNearbyDepthRadiusPx = 5;
  // The 95th percentile of the frame's valid depths (metres; 0 = unknown): how far the depth
  // camera measured in this frame. A keypoint with nothing measured around it most likely looks
  // beyond that range.
  float far_depth() const { return far_depth_m_; }
  const ScaleLevels& levels() const { return levels_; }

  // The observation of keypoint i for the reprojection cost (information = 1 / sigma^2 of its
  // level, disparity information from the sensor's disparity_sigma_px).
  KeypointObservation Observation(int i) const;
  // Back-projection of keypoint i with its depth, in the camera frame (requires HasDepth(i)).
  Eigen::Vector3d PointInCam(int i, const PinholeCamera& camera) const;

  // Indices of keypoints within `radius_px` (Euclidean) of (x, y) whose level is in
  // [min_level, max_level] (max_level < 0: no upper bound). Ascending index order.
  std::vector<int> FeaturesInArea(double x, double y, double radius_px, int min_level = 0,
                                  int max_level = -1) const;

 private:
  void Finish(const RgbdSensor& sensor);  // Undistortion, u_r, grid.

  std::vector<cv::KeyPoint> keypoints_;
  cv::Mat descriptors_;
  std::vector<float> depth_m_;
  std::vector<float> nearby_min_depth_m_;
  float far_depth_m_ = 0.0f;
  std::vector<float> u_right_;
  double disparity_information_ = 0.0;
  ScaleLevels levels_;
  std::optional<KeypointGrid> grid_;
};

}  // namespace dynorb
