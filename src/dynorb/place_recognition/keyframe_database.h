// KeyframeDatabase: an inverted index from vocabulary words to the keyframes whose bag of words
// contains them, for place recognition (relocalisation over the whole map, later loop detection).
// Not thread-safe by itself: MapData owns one and changes it under the Map's lock.
#pragma once

#include <map>
#include <set>
#include <vector>

#include "dynorb/core/ids.h"
#include "dynorb/place_recognition/vocabulary.h"

namespace dynorb {

struct ScoredKeyframe {
  KeyframeId keyframe = kNoKeyframe;
  double score = 0.0;  // BowScore with the query
  int common_words = 0;
};

class KeyframeDatabase {
 public:
  // Replaces any earlier entry of `keyframe`.
  void Add(KeyframeId keyframe, const BowVector& bow);
  void Erase(KeyframeId keyframe);
  bool Contains(KeyframeId keyframe) const { return vectors_.count(keyframe) != 0; }
  size_t size() const { return vectors_.size(); }
  const BowVector& bow(KeyframeId keyframe) const { return vectors_.at(keyframe); }

  // Keyframes sharing words with `query`, those with at least `min_common_fraction` of the best
  // keyframe's number of shared words (ORB-SLAM2: 0.8), scored; best score first, ties by id.
  // Keyframes in `excluded` take no part (neither returned nor setting the best count).
  std::vector<ScoredKeyframe> Query(const BowVector& query, double min_common_fraction = 0.8,
                                    const std::set<KeyframeId>& excluded = {}) const;

 private:
  std::map<uint32_t, std::vector<KeyframeId>> inverted_;  // word -> keyframes, ascending ids
  std::map<KeyframeId, BowVector> vectors_;
};

}  // namespace dynorb
