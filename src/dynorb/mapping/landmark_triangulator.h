// Creates new landmarks by matching the unmatched keypoints of a new keyframe with those of its
// best covisible keyframes and triangulating them (ORB-SLAM2 LocalMapping::CreateNewMapPoints).
// Candidate pairs: descriptor distance <= strict_max_distance, keypoint of the neighbour within
// 3.84 sigma^2 of the epipolar line (1-dof chi^2, 95 %), consistent orientation. The 3-D point
// comes from DLT triangulation when the rays' parallax exceeds the depth-based one (and 5 degrees
// when a keypoint has depth — see the .cc), otherwise from the keypoint depth with the better
// parallax. Accepted if in front of both cameras, reprojecting
// within the chi^2 gates in both and with distances consistent with the pyramid levels.
// Requires the map write lock (MapData&).
#pragma once

#include <vector>

#include "dynorb/map/map.h"
#include "dynorb/mapping/mapper_options.h"

namespace dynorb {

// Returns the ids of the created landmarks.
std::vector<LandmarkId> TriangulateNewLandmarks(MapData* map, KeyframeId keyframe, const RgbdSensor& sensor,
                                                const LocalMapperOptions& options);

}  // namespace dynorb
