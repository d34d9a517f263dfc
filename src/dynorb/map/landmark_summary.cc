#include "dynorb/map/landmark_summary.h"

#include <algorithm>

namespace dynorb {

LandmarkOrigin OriginOf(const MapData& map, const Landmark& landmark) {
  LandmarkOrigin origin;
  for (const auto& [kf_id, index] : landmark.observations) {  // Keyframe ids grow with time.
    if (!map.HasKeyframe(kf_id)) continue;
    const Keyframe& kf = map.keyframe(kf_id);
    if (kf.features == nullptr || index < 0 || index >= kf.features->size()) continue;
    origin.known = true;
    origin.keyframe = kf_id;
    origin.timestamp_s = kf.timestamp_s;
    origin.keypoint = kf.features->keypoint(index);
    break;
  }
  return origin;
}

std::vector<size_t> KnownOriginsByStamp(const std::vector<LandmarkOrigin>& origins) {
  std::vector<size_t> order;
  for (size_t i = 0; i < origins.size(); ++i) {
    if (origins[i].known) order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(), [&origins](size_t a, size_t b) {
    return origins[a].timestamp_s < origins[b].timestamp_s;
  });
  return order;
}

std::vector<LandmarkSummary> SummarizeLandmarks(const MapData& map) {
  std::vector<LandmarkSummary> out;
  out.reserve(map.landmarks().size());
  for (const auto& [id, landmark] : map.landmarks()) {
    LandmarkSummary s;
    s.id = id;
    s.point_in_world = landmark.point_in_world;
    s.num_observations = landmark.NumObservations();
    s.origin = OriginOf(map, landmark);
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace dynorb
