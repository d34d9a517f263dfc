// LocalMapper: processes each new keyframe (ORB-SLAM2's LocalMapping, one keyframe per call):
//   1. update the keyframe's landmarks (normals, distance ranges, descriptors) and covisibility;
//   2. cull recent landmarks that are rarely found where predicted or seen by too few keyframes;
//   3. triangulate new landmarks with the best covisible keyframes;
//   4. fuse duplicate landmarks with the first/second-ring neighbours;
//   5. local bundle adjustment (snapshot -> solve unlocked -> commit);
//   6. cull redundant keyframes (>= 90 % of their close landmarks seen by >= 3 other keyframes).
// ProcessOne() knows nothing about threads; in parallel mode a Worker calls it. Owns only the
// list of recent landmarks; all map access goes through the Map's lock.
#pragma once

#include <vector>

#include "dynorb/map/map.h"
#include "dynorb/mapping/local_bundle_adjustment.h"
#include "dynorb/mapping/mapper_options.h"

namespace dynorb {

struct MapperStepStats {
  int created_landmarks = 0;
  int culled_landmarks = 0;
  int fused = 0;
  int culled_keyframes = 0;
  LocalBaStats bundle_adjustment;
  double update_ms = 0.0, triangulate_ms = 0.0, fuse_ms = 0.0, bundle_adjustment_ms = 0.0, cull_ms = 0.0;
  double total_ms = 0.0;
};

class LocalMapper {
 public:
  LocalMapper(const RgbdSensor& sensor, const LocalMapperOptions& options, Map* map);
  MapperStepStats ProcessOne(KeyframeId keyframe);

 private:
  int CullRecentLandmarks(MapData* map, KeyframeId keyframe);
  int CullKeyframes(MapData* map, KeyframeId keyframe);

  RgbdSensor sensor_;
  LocalMapperOptions options_;
  Map* map_;
  std::vector<LandmarkId> recent_landmarks_;
};

}  // namespace dynorb
