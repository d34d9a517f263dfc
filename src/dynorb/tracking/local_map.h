// LocalMap: an immutable snapshot of the part of the map the tracker matches against — the
// local keyframes (those sharing landmarks with the current frame, plus their best covisibles,
// children and parents, as ORB-SLAM2's UpdateLocalKeyFrames) and all their landmarks. Built
// under the map's read lock, then used without any lock.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "dynorb/core/ids.h"
#include "dynorb/map/map.h"
#include "dynorb/tracking/frame.h"

namespace dynorb {

struct LandmarkView {
  LandmarkId id = kNoLandmark;
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal_in_world = Eigen::Vector3d::Zero();
  double min_distance_m = 0.0;
  double max_distance_m = 0.0;
  std::array<uint8_t, 32> descriptor{};
};

LandmarkView MakeLandmarkView(const Landmark& landmark);

struct LocalMap {
  KeyframeId reference_keyframe = kNoKeyframe;  // The local keyframe sharing most landmarks.
  std::vector<KeyframeId> keyframes;
  std::vector<LandmarkView> landmarks;
};

// `max_keyframes` caps the local keyframe set (ORB-SLAM2: 80).
LocalMap BuildLocalMap(const MapData& map, const Frame& frame, int max_keyframes = 80);

}  // namespace dynorb
