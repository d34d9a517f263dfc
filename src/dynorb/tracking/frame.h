// Frame: the tracker's working state for the current image — its features (shared, immutable),
// the landmark matched to each keypoint, outlier flags from pose optimisation and the pose.
// Owned by the Tracker; not shared between threads.
#pragma once

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "dynorb/core/ids.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/map/frame_features.h"

namespace dynorb {

struct Frame {
  FrameId id = 0;
  double timestamp_s = 0.0;
  std::shared_ptr<const FrameFeatures> features;
  std::vector<LandmarkId> landmarks;             // Per keypoint; kNoLandmark if unmatched.
  std::vector<Eigen::Vector3d> landmark_points;  // Per keypoint: world position when matched.
  std::vector<bool> outlier;                     // Per keypoint: rejected by pose optimisation.
  std::vector<bool> outlier_at_fixed_gates;      // Per keypoint: outside the unscaled (1-px) gates.
  Rigid3d cam_from_world;
  KeyframeId reference_keyframe = kNoKeyframe;
  // Of the detected keypoints, the fraction the keypoint filter removed (0 without a filter).
  double filtered_fraction = 0.0;
  // The keypoints the filter saw move (FilterOutput::moving_points) and the frame's depth
  // (CV_32F metres), for the landmarks' dynamic votes (dynamic_votes.h).
  std::vector<cv::Point2f> moving_points;
  cv::Mat depth_m;

  Frame() = default;
  Frame(FrameId frame_id, double stamp_s, std::shared_ptr<const FrameFeatures> f)
      : id(frame_id), timestamp_s(stamp_s), features(std::move(f)) {
    ResetMatches();
  }
  void ResetMatches() {
    const int n = features ? features->size() : 0;
    landmarks.assign(n, kNoLandmark);
    landmark_points.assign(n, Eigen::Vector3d::Zero());
    outlier.assign(n, false);
    outlier_at_fixed_gates.assign(n, false);
  }
  void SetMatch(int index, LandmarkId lm, const Eigen::Vector3d& point_in_world) {
    landmarks[index] = lm;
    landmark_points[index] = point_in_world;
    outlier[index] = false;
    outlier_at_fixed_gates[index] = false;
  }
  int NumMatches() const {
    int n = 0;
    for (size_t i = 0; i < landmarks.size(); ++i) n += (landmarks[i] != kNoLandmark && !outlier[i]) ? 1 : 0;
    return n;
  }
};

}  // namespace dynorb
