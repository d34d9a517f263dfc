#include "dynorb/map/place_candidates.h"

#include <algorithm>
#include <map>

namespace dynorb {

std::vector<ScoredKeyframe> PlaceCandidates(const MapData& map, const BowVector& query,
                                            const std::set<KeyframeId>& excluded,
                                            const PlaceQueryOptions& options) {
  std::map<KeyframeId, double> score;
  for (const ScoredKeyframe& s :
       map.keyframe_database().Query(query, options.min_common_fraction, excluded)) {
    if (!map.HasKeyframe(s.keyframe) || s.score < options.min_score) continue;
    score[s.keyframe] = s.score;
  }
  // Each scored keyframe's group, represented by its best-scoring member, with the group's
  // accumulated score.
  std::vector<ScoredKeyframe> groups;
  double best_accumulated = 0.0;
  for (const auto& [kf, s] : score) {
    ScoredKeyframe group{kf, s, 0};
    double best_score = s;
    for (KeyframeId other : map.BestCovisibles(kf, options.group_covisibles)) {
      auto it = score.find(other);
      if (it == score.end()) continue;
      group.score += it->second;
      if (it->second > best_score || (it->second == best_score && other < group.keyframe)) {
        best_score = it->second;
        group.keyframe = other;
      }
    }
    groups.push_back(group);
    best_accumulated = std::max(best_accumulated, group.score);
  }
  std::map<KeyframeId, ScoredKeyframe> best_of_group;  // representative -> its best group
  for (const ScoredKeyframe& group : groups) {
    if (group.score < options.min_group_fraction * best_accumulated) continue;
    auto it = best_of_group.find(group.keyframe);
    if (it == best_of_group.end() || it->second.score < group.score)
      best_of_group[group.keyframe] = group;
  }
  std::vector<ScoredKeyframe> out;
  for (const auto& [kf, group] : best_of_group) out.push_back(group);
  std::sort(out.begin(), out.end(), [](const ScoredKeyframe& a, const ScoredKeyframe& b) {
    return a.score != b.score ? a.score > b.score : a.keyframe < b.keyframe;
  });
  return out;
}

}  // namespace dynorb
