#include "dynorb/mapping/landmark_fuser.h"

#include <algorithm>
#include <set>

#include "dynorb/features/orb_matcher.h"
#include "dynorb/map/match_rules.h"
#include "dynorb/optimization/reprojection_cost.h"

namespace dynorb {
namespace {

// Projects each landmark of `landmarks` into keyframe `target` and fuses it there.
void FuseInto(MapData* map, KeyframeId target, const std::vector<LandmarkId>& landmarks, const RgbdSensor& sensor,
              const LocalMapperOptions& options, FuseStats* stats) {
  for (LandmarkId id : landmarks) {
    if (!map->HasLandmark(id) || !map->HasKeyframe(target)) continue;
    const Keyframe& kf = map->keyframe(target);
    const Landmark& lm = map->landmark(id);
    if (lm.observations.count(target) != 0 || lm.descriptor.empty()) continue;
    const FrameFeatures& f = *kf.features;
    const Eigen::Vector3d p = kf.cam_from_world * lm.point_in_world;
    if (p.z() <= 0.0) continue;
    const Eigen::Vector2d uv = sensor.camera.Project(p);
    if (!sensor.camera.InImage(uv)) continue;
    const Eigen::Vector3d ray = lm.point_in_world - kf.CameraCenterInWorld();
    const double distance = ray.norm();
    if (distance < 0.8 * lm.min_distance_m || distance > 1.2 * lm.max_distance_m) continue;
    if (ray.dot(lm.normal_in_world) < 0.5 * distance) continue;
    const int level = PredictLevel(lm.max_distance_m, distance, f.levels());
    const double radius = options.fuse_radius_px * f.levels().scale[level];
    int best = -1, best_distance = options.strict_max_distance + 1;
    for (int c : f.FeaturesInArea(uv.x(), uv.y(), radius, std::max(0, level - 1), level)) {
      const KeypointObservation obs = f.Observation(c);
      const double gate = obs.IsStereo() ? 7.8 : 5.991;
      if (ReprojectionChi2(sensor.camera, sensor.bf, obs, p) > gate) continue;
      const int d = HammingDistance256(lm.descriptor.ptr<uint8_t>(0), f.descriptor(c));
      if (d < best_distance) {
        best_distance = d;
        best = c;
      }
    }
    if (best < 0) continue;
    const LandmarkId existing = kf.landmarks[best];
    if (existing == kNoLandmark) {
      map->AddObservation(id, target, best);
      ++stats->added_observations;
    } else if (existing != id && map->HasLandmark(existing)) {
      if (map->landmark(existing).NumObservations() > lm.NumObservations()) {
        map->ReplaceLandmark(id, existing);
      } else {
        map->ReplaceLandmark(existing, id);
      }
      ++stats->merged;
    }
  }
}

std::vector<LandmarkId> LandmarksOf(const MapData& map, KeyframeId kf) {
  std::vector<LandmarkId> result;
  for (LandmarkId lm : map.keyframe(kf).landmarks) {
    if (lm != kNoLandmark) result.push_back(lm);
  }
  return result;
}

}  // namespace

FuseStats FuseWithNeighbours(MapData* map, KeyframeId keyframe, const RgbdSensor& sensor,
                             const LocalMapperOptions& options) {
  FuseStats stats;
  std::vector<KeyframeId> targets;
  std::set<KeyframeId> seen = {keyframe};
  for (KeyframeId n : map->BestCovisibles(keyframe, options.fusion_neighbours)) {
    if (seen.insert(n).second) targets.push_back(n);
  }
  const size_t first_ring = targets.size();
  for (size_t i = 0; i < first_ring; ++i) {
    for (KeyframeId n2 : map->BestCovisibles(targets[i], options.fusion_second_neighbours)) {
      if (seen.insert(n2).second) targets.push_back(n2);
    }
  }
  // The keyframe's landmarks into each neighbour.
  for (KeyframeId target : targets) FuseInto(map, target, LandmarksOf(*map, keyframe), sensor, options, &stats);
  // The neighbours' landmarks into the keyframe.
  std::vector<LandmarkId> candidates;
  std::set<LandmarkId> unique;
  for (KeyframeId target : targets) {
    if (!map->HasKeyframe(target)) continue;
    for (LandmarkId lm : LandmarksOf(*map, target)) {
      if (unique.insert(lm).second) candidates.push_back(lm);
    }
  }
  FuseInto(map, keyframe, candidates, sensor, options, &stats);
  for (LandmarkId lm : LandmarksOf(*map, keyframe)) {
    map->UpdateLandmarkGeometry(lm);
    map->UpdateLandmarkDescriptor(lm);
  }
  map->UpdateConnections(keyframe);
  return stats;
}

FuseStats FuseLandmarksInto(MapData* map, KeyframeId target,
                            const std::vector<LandmarkId>& landmarks, const RgbdSensor& sensor,
                            const LocalMapperOptions& options) {
  FuseStats stats;
  FuseInto(map, target, landmarks, sensor, options, &stats);
  return stats;
}

}  // namespace dynorb
