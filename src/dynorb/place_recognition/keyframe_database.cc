#include "dynorb/place_recognition/keyframe_database.h"

#include <algorithm>
#include <cmath>

namespace dynorb {

void KeyframeDatabase::Add(KeyframeId keyframe, const BowVector& bow) {
  Erase(keyframe);
  vectors_[keyframe] = bow;
  for (const BowEntry& e : bow) {
    std::vector<KeyframeId>& list = inverted_[e.word];
    list.insert(std::upper_bound(list.begin(), list.end(), keyframe), keyframe);
  }
}

void KeyframeDatabase::Erase(KeyframeId keyframe) {
  auto it = vectors_.find(keyframe);
  if (it == vectors_.end()) return;
  for (const BowEntry& e : it->second) {
    auto list = inverted_.find(e.word);
    if (list == inverted_.end()) continue;
    auto pos = std::lower_bound(list->second.begin(), list->second.end(), keyframe);
    if (pos != list->second.end() && *pos == keyframe) list->second.erase(pos);
    if (list->second.empty()) inverted_.erase(list);
  }
  vectors_.erase(it);
}

std::vector<ScoredKeyframe> KeyframeDatabase::Query(const BowVector& query,
                                                    double min_common_fraction,
                                                    const std::set<KeyframeId>& excluded) const {
  std::map<KeyframeId, int> common;
  for (const BowEntry& e : query) {
    auto list = inverted_.find(e.word);
    if (list == inverted_.end()) continue;
    for (KeyframeId kf : list->second) {
      if (!excluded.count(kf)) ++common[kf];
    }
  }
  int max_common = 0;
  for (const auto& [kf, n] : common) max_common = std::max(max_common, n);
  const int min_common = static_cast<int>(std::ceil(min_common_fraction * max_common));
  std::vector<ScoredKeyframe> out;
  for (const auto& [kf, n] : common) {
    if (n < std::max(1, min_common)) continue;
    out.push_back({kf, BowScore(query, vectors_.at(kf)), n});
  }
  std::sort(out.begin(), out.end(), [](const ScoredKeyframe& a, const ScoredKeyframe& b) {
    return a.score != b.score ? a.score > b.score : a.keyframe < b.keyframe;
  });
  return out;
}

}  // namespace dynorb
