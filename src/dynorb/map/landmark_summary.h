// The map's landmarks as they stand, each with where it was made: for exporting the map
// (`dynorb run --save-map`) and for checking it against ground-truth masks.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "dynorb/core/ids.h"
#include "dynorb/map/map.h"

namespace dynorb {

// Where a landmark was made: the oldest keyframe still in the map that observes it, and the
// keypoint there (full-resolution pixels).
struct LandmarkOrigin {
  bool known = false;  // false when none of its observing keyframes is in the map any more
  KeyframeId keyframe = kNoKeyframe;
  double timestamp_s = 0.0;
  cv::KeyPoint keypoint;
};
LandmarkOrigin OriginOf(const MapData& map, const Landmark& landmark);
// The indices of the known origins, ordered by their stamp (ties in index order): visiting them
// in this order needs one keyframe's image (or mask) at a time.
std::vector<size_t> KnownOriginsByStamp(const std::vector<LandmarkOrigin>& origins);

struct LandmarkSummary {
  LandmarkId id = kNoLandmark;
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  int num_observations = 0;  // keyframes observing it
  LandmarkOrigin origin;
};
// Every landmark of the map, by id.
std::vector<LandmarkSummary> SummarizeLandmarks(const MapData& map);

}  // namespace dynorb
