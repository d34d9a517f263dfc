// Fuses duplicated landmarks between a new keyframe and its neighbourhood (ORB-SLAM2
// LocalMapping::SearchInNeighbors + ORBmatcher::Fuse): the keyframe's landmarks are projected into
// the first- and second-ring covisible keyframes and theirs into the keyframe; a landmark landing
// on a keypoint (within fuse_radius_px x level scale, chi^2 gate on the reprojection, descriptor
// distance <= strict_max_distance) either adds an observation or, if that keypoint already has a
// landmark, the two are merged into the one with more observations.
// Requires the map write lock (MapData&).
#pragma once

#include "dynorb/map/map.h"
#include "dynorb/mapping/mapper_options.h"

namespace dynorb {

struct FuseStats {
  int added_observations = 0;
  int merged = 0;
};

FuseStats FuseWithNeighbours(MapData* map, KeyframeId keyframe, const RgbdSensor& sensor,
                             const LocalMapperOptions& options);

// The same for a given set of landmarks projected into one keyframe (loop closing fuses the loop
// side's landmarks into the corrected keyframes).
FuseStats FuseLandmarksInto(MapData* map, KeyframeId target,
                            const std::vector<LandmarkId>& landmarks, const RgbdSensor& sensor,
                            const LocalMapperOptions& options);

}  // namespace dynorb
