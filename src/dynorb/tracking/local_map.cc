#include "dynorb/tracking/local_map.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <set>

namespace dynorb {

LandmarkView MakeLandmarkView(const Landmark& landmark) {
  LandmarkView v;
  v.id = landmark.id;
  v.point_in_world = landmark.point_in_world;
  v.normal_in_world = landmark.normal_in_world;
  v.min_distance_m = landmark.min_distance_m;
  v.max_distance_m = landmark.max_distance_m;
  if (!landmark.descriptor.empty()) std::memcpy(v.descriptor.data(), landmark.descriptor.data, 32);
  return v;
}

LocalMap BuildLocalMap(const MapData& map, const Frame& frame, int max_keyframes) {
  LocalMap local;
  std::map<KeyframeId, int> counts;
  for (size_t i = 0; i < frame.landmarks.size(); ++i) {
    const LandmarkId lm = frame.landmarks[i];
    if (lm == kNoLandmark || frame.outlier[i] || !map.HasLandmark(lm)) continue;
    for (const auto& [kf, index] : map.landmark(lm).observations) ++counts[kf];
  }
  if (counts.empty() && map.HasKeyframe(frame.reference_keyframe)) counts[frame.reference_keyframe] = 1;
  if (counts.empty()) return local;

  std::vector<std::pair<int, KeyframeId>> by_count;
  for (const auto& [kf, c] : counts) by_count.push_back({c, kf});
  std::stable_sort(by_count.begin(), by_count.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  local.reference_keyframe = by_count.front().second;

  std::set<KeyframeId> included;
  for (const auto& [c, kf] : by_count) {
    if (static_cast<int>(local.keyframes.size()) >= max_keyframes) break;
    if (included.insert(kf).second) local.keyframes.push_back(kf);
  }
  // Neighbours of the first-ring keyframes: one best covisible, one child, the parent.
  const size_t first_ring = local.keyframes.size();
  for (size_t i = 0; i < first_ring && static_cast<int>(local.keyframes.size()) < max_keyframes; ++i) {
    const Keyframe& kf = map.keyframe(local.keyframes[i]);
    for (KeyframeId neighbour : map.BestCovisibles(kf.id, 10)) {
      if (included.insert(neighbour).second) {
        local.keyframes.push_back(neighbour);
        break;
      }
    }
    for (KeyframeId child : kf.children) {
      if (map.HasKeyframe(child) && included.insert(child).second) {
        local.keyframes.push_back(child);
        break;
      }
    }
    if (kf.parent != kNoKeyframe && map.HasKeyframe(kf.parent) && included.insert(kf.parent).second) {
      local.keyframes.push_back(kf.parent);
    }
  }

  std::set<LandmarkId> seen;
  for (KeyframeId kf : local.keyframes) {
    for (LandmarkId lm : map.keyframe(kf).landmarks) {
      if (lm == kNoLandmark || !seen.insert(lm).second) continue;
      local.landmarks.push_back(MakeLandmarkView(map.landmark(lm)));
    }
  }
  return local;
}

}  // namespace dynorb
