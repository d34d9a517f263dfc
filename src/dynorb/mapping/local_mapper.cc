#include "dynorb/mapping/local_mapper.h"

#include "dynorb/core/error.h"
#include "dynorb/core/timer.h"
#include "dynorb/mapping/landmark_fuser.h"
#include "dynorb/mapping/landmark_triangulator.h"

namespace dynorb {

void LocalMapperOptions::Validate() const {
  if (triangulation_neighbours < 0 || fusion_neighbours < 0 || fusion_second_neighbours < 0 ||
      fuse_radius_px <= 0.0 || local_ba_keyframes < 1 || local_ba_fixed_keyframes < 0 || strict_max_distance < 0 || strict_max_distance > 256 || min_found_ratio < 0.0 ||
      min_found_ratio > 1.0 || redundant_ratio <= 0.0 || redundant_ratio > 1.0 || redundant_observers < 1 ||
      free_space_ratio < 0.0 || free_space_ratio > 1.0) {
    throw InputError("local mapper options out of range (see mapping/mapper_options.h)");
  }
  bundle_adjustment.Validate();
}

LocalMapper::LocalMapper(const RgbdSensor& sensor, const LocalMapperOptions& options, Map* map)
    : sensor_(sensor), options_(options), map_(map) {
  options_.Validate();
}

MapperStepStats LocalMapper::ProcessOne(KeyframeId keyframe) {
  MapperStepStats stats;
  Stopwatch total;
  Stopwatch watch;
  const bool exists = map_->Write([&](MapData& map) {
    if (!map.HasKeyframe(keyframe)) return false;
    for (LandmarkId lm : map.keyframe(keyframe).landmarks) {
      if (lm == kNoLandmark) continue;
      map.UpdateLandmarkGeometry(lm);
      map.UpdateLandmarkDescriptor(lm);
      if (map.landmark(lm).first_keyframe == keyframe) recent_landmarks_.push_back(lm);
    }
    map.UpdateConnections(keyframe);
    stats.culled_landmarks = CullRecentLandmarks(&map, keyframe);
    return true;
  });
  stats.update_ms = watch.ElapsedMs();
  if (!exists) return stats;

  watch.Restart();
  map_->Write([&](MapData& map) {
    const std::vector<LandmarkId> created = TriangulateNewLandmarks(&map, keyframe, sensor_, options_);
    recent_landmarks_.insert(recent_landmarks_.end(), created.begin(), created.end());
    stats.created_landmarks = static_cast<int>(created.size());
    return 0;
  });
  stats.triangulate_ms = watch.ElapsedMs();

  watch.Restart();
  map_->Write([&](MapData& map) {
    const FuseStats fuse = FuseWithNeighbours(&map, keyframe, sensor_, options_);
    stats.fused = fuse.added_observations + fuse.merged;
    return 0;
  });
  stats.fuse_ms = watch.ElapsedMs();

  watch.Restart();
  const size_t num_keyframes = map_->Read([](const MapData& map) { return map.NumKeyframes(); });
  if (options_.local_bundle_adjustment && num_keyframes > 2) {
    stats.bundle_adjustment = RunLocalBundleAdjustment(map_, keyframe, sensor_, options_);
  }
  stats.bundle_adjustment_ms = watch.ElapsedMs();

  watch.Restart();
  if (options_.keyframe_culling) {
    stats.culled_keyframes = map_->Write([&](MapData& map) { return CullKeyframes(&map, keyframe); });
  }
  stats.cull_ms = watch.ElapsedMs();
  stats.total_ms = total.ElapsedMs();
  return stats;
}

int LocalMapper::CullRecentLandmarks(MapData* map, KeyframeId keyframe) {
  constexpr int kMinWeightedObservations = 3;  // ORB-SLAM2 RGB-D: culled when <= 3 (weighted).
  int culled = 0;
  std::vector<LandmarkId> kept;
  for (LandmarkId id : recent_landmarks_) {
    if (!map->HasLandmark(id)) continue;
    const Landmark& lm = map->landmark(id);
    const KeyframeId age = keyframe >= lm.first_keyframe ? keyframe - lm.first_keyframe : 0;
    if (lm.FoundRatio() < options_.min_found_ratio) {
      map->EraseLandmark(id);
      ++culled;
    } else if (age >= 2 && map->WeightedObservations(id) <= kMinWeightedObservations) {
      map->EraseLandmark(id);
      ++culled;
    } else if (age < 3) {
      kept.push_back(id);
    }
  }
  recent_landmarks_ = std::move(kept);
  return culled;
}

int LocalMapper::CullKeyframes(MapData* map, KeyframeId keyframe) {
  int culled = 0;
  const std::vector<KeyframeId> local = map->keyframe(keyframe).ordered_covisibles;
  const KeyframeId root = map->keyframes().begin()->first;
  for (KeyframeId id : local) {
    // Ids grow, and the mapper takes keyframes in order: a newer covisible keyframe is still
    // queued (parallel mode) and is judged once it has been processed itself.
    if (id == root || id > keyframe || !map->HasKeyframe(id) || map->keyframe(id).keep) continue;
    const Keyframe& kf = map->keyframe(id);
    const FrameFeatures& f = *kf.features;
    int close = 0, redundant = 0;
    for (size_t i = 0; i < kf.landmarks.size(); ++i) {
      const LandmarkId lm = kf.landmarks[i];
      if (lm == kNoLandmark || !f.IsClose(static_cast<int>(i), sensor_.th_depth_m)) continue;
      ++close;
      if (map->WeightedObservations(lm) <= 3) continue;
      const int level = f.keypoint(static_cast<int>(i)).octave;
      int observers = 0;
      for (const auto& [other, index] : map->landmark(lm).observations) {
        if (other == id) continue;
        if (map->keyframe(other).features->keypoint(index).octave <= level + 1) ++observers;
        if (observers >= options_.redundant_observers) break;
      }
      if (observers >= options_.redundant_observers) ++redundant;
    }
    if (close > 0 && redundant > options_.redundant_ratio * close) {
      map->EraseKeyframe(id);
      ++culled;
    }
  }
  return culled;
}

}  // namespace dynorb
