#include "dynorb/mapping/local_bundle_adjustment.h"

#include <algorithm>
#include <map>
#include <set>

#include "dynorb/mapping/ba_snapshot.h"
#include "dynorb/optimization/bundle_adjuster.h"

namespace dynorb {
namespace {

BaSnapshot TakeSnapshot(const MapData& map, KeyframeId keyframe,
                        const LocalMapperOptions& options) {
  BaSnapshot s;
  s.epoch = map.correction_epoch();
  std::map<KeyframeId, size_t> kf_index;
  std::map<LandmarkId, size_t> lm_index;
  auto add_keyframe = [&](KeyframeId id, bool fixed) {
    kf_index[id] = s.keyframes.size();
    s.keyframe_ids.push_back(id);
    BaKeyframe kf;
    kf.cam_from_world = map.keyframe(id).cam_from_world;
    kf.fixed = fixed || id == map.keyframes().begin()->first;  // The first keyframe anchors the map.
    s.keyframes.push_back(kf);
  };
  add_keyframe(keyframe, false);
  for (KeyframeId id : map.BestCovisibles(keyframe, std::max(0, options.local_ba_keyframes - 1))) {
    add_keyframe(id, false);
  }
  const size_t num_local = s.keyframes.size();
  for (size_t k = 0; k < num_local; ++k) {
    for (LandmarkId lm : map.keyframe(s.keyframe_ids[k]).landmarks) {
      if (lm == kNoLandmark || lm_index.count(lm)) continue;
      lm_index[lm] = s.points.size();
      s.landmark_ids.push_back(lm);
      s.points.push_back(map.landmark(lm).point_in_world);
    }
  }
  // Fixed observers outside the window: the ones sharing most landmarks with it.
  std::map<KeyframeId, int> outside;
  for (LandmarkId lm : s.landmark_ids) {
    for (const auto& [kf, index] : map.landmark(lm).observations) {
      if (!kf_index.count(kf)) ++outside[kf];
    }
  }
  std::vector<std::pair<int, KeyframeId>> ranked;
  for (const auto& [kf, count] : outside) ranked.push_back({count, kf});
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (size_t i = 0; i < ranked.size() && static_cast<int>(i) < options.local_ba_fixed_keyframes; ++i) {
    add_keyframe(ranked[i].second, true);
  }
  for (size_t l = 0; l < s.landmark_ids.size(); ++l) {
    for (const auto& [kf, index] : map.landmark(s.landmark_ids[l]).observations) {
      auto it = kf_index.find(kf);
      if (it == kf_index.end()) continue;  // An observer beyond the fixed set: left out.
      s.AddObservation(map, it->second, l, index);
    }
  }
  return s;
}

}  // namespace

LocalBaStats RunLocalBundleAdjustment(Map* map, KeyframeId keyframe, const RgbdSensor& sensor,
                                      const LocalMapperOptions& options) {
  LocalBaStats stats;
  const BaSnapshot s = map->Read([&](const MapData& data) {
    return data.HasKeyframe(keyframe) ? TakeSnapshot(data, keyframe, options) : BaSnapshot{};
  });
  if (s.observations.empty()) return stats;
  for (const BaKeyframe& kf : s.keyframes) (kf.fixed ? stats.fixed_keyframes : stats.free_keyframes)++;
  stats.landmarks = static_cast<int>(s.points.size());
  stats.observations = static_cast<int>(s.observations.size());

  const BundleAdjusterResult r =
      RunBundleAdjustment(sensor.camera, sensor.bf, s.keyframes, s.points, s.observations, options.bundle_adjustment);
  stats.initial_cost = r.initial_cost;
  stats.final_cost = r.final_cost;
  if (r.failed) {  // Nothing usable to write (the outlier flags were judged on bad values too).
    stats.discarded = true;
    return stats;
  }

  map->Write([&](MapData& data) {
    // A global BA in the background moved the whole map meanwhile: this window's result is in
    // the old frame, and committing it would tear the window from the rest.
    if (data.correction_epoch() != s.epoch) {
      stats.discarded = true;
      return 0;
    }
    stats.removed_observations = EraseOutlierObservations(&data, s, r.observation_inlier);
    for (size_t k = 0; k < s.keyframes.size(); ++k) {
      if (!s.keyframes[k].fixed && data.HasKeyframe(s.keyframe_ids[k])) {
        data.keyframe(s.keyframe_ids[k]).cam_from_world = r.cam_from_world[k];
      }
    }
    for (size_t l = 0; l < s.landmark_ids.size(); ++l) {
      if (!data.HasLandmark(s.landmark_ids[l])) continue;
      data.landmark(s.landmark_ids[l]).point_in_world = r.points_in_world[l];
      data.UpdateLandmarkGeometry(s.landmark_ids[l]);
    }
    return 0;
  });
  return stats;
}

}  // namespace dynorb
