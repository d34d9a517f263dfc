#include "dynorb/mapping/ba_snapshot.h"

namespace dynorb {

void BaSnapshot::AddObservation(const MapData& map, size_t keyframe_index, size_t landmark_index,
                                int keypoint) {
  BaObservation obs;
  obs.keyframe_index = keyframe_index;
  obs.landmark_index = landmark_index;
  obs.keypoint = map.keyframe(keyframe_ids[keyframe_index]).features->Observation(keypoint);
  observations.push_back(obs);
  keypoint_index.push_back(keypoint);
}

int EraseOutlierObservations(MapData* map, const BaSnapshot& snapshot,
                             const std::vector<bool>& inlier) {
  int erased = 0;
  for (size_t o = 0; o < snapshot.observations.size(); ++o) {
    if (inlier[o]) continue;
    const KeyframeId kf = snapshot.keyframe_ids[snapshot.observations[o].keyframe_index];
    const LandmarkId lm = snapshot.landmark_ids[snapshot.observations[o].landmark_index];
    if (!map->HasLandmark(lm)) continue;
    const auto& observations = map->landmark(lm).observations;
    const auto it = observations.find(kf);
    if (it != observations.end() && it->second == snapshot.keypoint_index[o]) {
      map->EraseObservation(lm, kf);
      ++erased;
    }
  }
  return erased;
}

}  // namespace dynorb
