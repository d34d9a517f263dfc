// Landmark: a 3-D map point observed by keyframes. Owned by MapData; refers to keyframes by id.
#pragma once

#include <map>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "dynorb/core/ids.h"

namespace dynorb {

struct Landmark {
  LandmarkId id = kNoLandmark;
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  cv::Mat descriptor;                       // 1 x 32 CV_8U: the observation descriptor with the
                                            // least median distance to the others.
  std::map<KeyframeId, int> observations;   // keyframe -> keypoint index.
  Eigen::Vector3d normal_in_world = Eigen::Vector3d::Zero();  // Mean unit viewing direction.
  double min_distance_m = 0.0;              // Scale-invariance range of the descriptor.
  double max_distance_m = 0.0;
  KeyframeId reference_keyframe = kNoKeyframe;
  KeyframeId first_keyframe = kNoKeyframe;
  FrameId first_frame = 0;
  int num_visible = 1;                      // Frames in whose frustum it was predicted.
  int num_found = 1;                        // Frames where it was matched.
  int dynamic_votes = 0;                    // Times observed moving since its last static inlier
                                            // match (tracking/dynamic_votes.h).

  double FoundRatio() const { return static_cast<double>(num_found) / std::max(1, num_visible); }
  int NumObservations() const { return static_cast<int>(observations.size()); }
};

}  // namespace dynorb
