#include "dynorb/loop_closing/global_bundle_adjustment.h"

#include <map>
#include <vector>

#include "dynorb/core/timer.h"

namespace dynorb {
namespace {

// The pose a keyframe missing from the snapshot gets: it keeps its pose relative to its nearest
// ancestor (spanning tree) that has one; unchanged if it has none.
Rigid3d PropagatedPose(const MapData& map, KeyframeId id,
                       std::map<KeyframeId, Rigid3d>* corrected) {
  const auto known = corrected->find(id);
  if (known != corrected->end()) return known->second;
  const Keyframe& k = map.keyframe(id);
  Rigid3d pose = k.cam_from_world;
  KeyframeId ancestor = k.parent;
  for (size_t steps = 0; ancestor != kNoKeyframe && map.HasKeyframe(ancestor) &&
                         !corrected->count(ancestor) && steps <= map.NumKeyframes();
       ++steps) {
    ancestor = map.keyframe(ancestor).parent;
  }
  if (ancestor != kNoKeyframe && corrected->count(ancestor)) {
    const Rigid3d& ancestor_now = map.keyframe(ancestor).cam_from_world;
    pose = k.cam_from_world * ancestor_now.Inverse() * corrected->at(ancestor);
  }
  (*corrected)[id] = pose;
  return pose;
}

}  // namespace

GlobalBundleAdjustment::GlobalBundleAdjustment(const MapData& map) {
  BaSnapshot& s = snapshot_;
  s.epoch = map.correction_epoch();
  std::map<KeyframeId, size_t> kf_index;
  for (const auto& [id, k] : map.keyframes()) {
    kf_index[id] = s.keyframes.size();
    s.keyframe_ids.push_back(id);
    BaKeyframe kf;
    kf.cam_from_world = k.cam_from_world;
    kf.fixed = s.keyframes.empty();  // The first keyframe anchors the map.
    s.keyframes.push_back(kf);
  }
  for (const auto& [lm, l] : map.landmarks()) {
    const size_t index = s.points.size();
    bool observed = false;
    for (const auto& [kf, keypoint] : l.observations) {
      const auto it = kf_index.find(kf);
      if (it == kf_index.end()) continue;
      s.AddObservation(map, it->second, index, keypoint);
      observed = true;
    }
    if (!observed) continue;
    s.landmark_ids.push_back(lm);
    s.points.push_back(l.point_in_world);
  }
  stats_.keyframes = static_cast<int>(s.keyframes.size());
  stats_.landmarks = static_cast<int>(s.points.size());
  stats_.observations = static_cast<int>(s.observations.size());
}

bool GlobalBundleAdjustment::Solve(const RgbdSensor& sensor, const BundleAdjusterOptions& options) {
  const BaSnapshot& s = snapshot_;
  if (s.observations.empty()) return false;
  result_ =
      RunBundleAdjustment(sensor.camera, sensor.bf, s.keyframes, s.points, s.observations, options);
  stats_.initial_cost = result_.initial_cost;
  stats_.final_cost = result_.final_cost;
  stats_.outlier_observations = 0;
  for (bool inlier : result_.observation_inlier) stats_.outlier_observations += inlier ? 0 : 1;
  solved_ = !result_.stopped && result_.converged;
  return solved_;
}

bool GlobalBundleAdjustment::Commit(MapData* map) {
  const BaSnapshot& s = snapshot_;
  if (!solved_ || map->correction_epoch() != s.epoch) return false;
  std::map<KeyframeId, Rigid3d> before;
  for (const auto& [id, k] : map->keyframes()) before[id] = k.cam_from_world;
  std::map<KeyframeId, Rigid3d> corrected;
  for (size_t k = 0; k < s.keyframe_ids.size(); ++k) {
    if (map->HasKeyframe(s.keyframe_ids[k]))
      corrected[s.keyframe_ids[k]] = result_.cam_from_world[k];
  }
  for (const auto& [id, pose] : before) {
    if (corrected.count(id)) continue;
    PropagatedPose(*map, id, &corrected);
    ++stats_.propagated_keyframes;
  }
  std::map<LandmarkId, size_t> in_snapshot;
  for (size_t l = 0; l < s.landmark_ids.size(); ++l) in_snapshot[s.landmark_ids[l]] = l;
  std::vector<LandmarkId> ids;
  for (const auto& [lm, l] : map->landmarks()) ids.push_back(lm);
  for (LandmarkId lm : ids) {
    const auto it = in_snapshot.find(lm);
    if (it != in_snapshot.end()) {
      map->landmark(lm).point_in_world = result_.points_in_world[it->second];
    } else if (map->MoveLandmarkWithKeyframe(lm, before, corrected)) {
      ++stats_.propagated_landmarks;
    }
  }
  // As the local BA does: observations beyond the gate (a mover's, a wrong match) leave the map.
  stats_.removed_observations = EraseOutlierObservations(map, s, result_.observation_inlier);
  ids.clear();
  for (const auto& [lm, l] : map->landmarks()) ids.push_back(lm);
  for (const auto& [id, pose] : corrected) map->keyframe(id).cam_from_world = pose;
  for (LandmarkId lm : ids) map->UpdateLandmarkGeometry(lm);
  map->NoteCorrection(std::move(before));
  stats_.committed = true;
  return true;
}

GlobalBaStats RunGlobalBundleAdjustment(Map* map, const RgbdSensor& sensor,
                                        const BundleAdjusterOptions& options) {
  Stopwatch watch;
  GlobalBundleAdjustment gba =
      map->Read([](const MapData& data) { return GlobalBundleAdjustment(data); });
  if (gba.Solve(sensor, options)) map->Correct([&](MapData& data) { return gba.Commit(&data); });
  GlobalBaStats stats = gba.stats();
  stats.ms = watch.ElapsedMs();
  return stats;
}

}  // namespace dynorb
