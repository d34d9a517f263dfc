// Place recognition over the map: which keyframes show the place a bag of words describes
// (ORB-SLAM2's relocalisation candidates). Keyframes sharing at least 80 % of the best one's
// shared words are scored against the query; each one's score is accumulated with those of its
// 10 best covisible keyframes that scored too (a place is seen by a group of keyframes, a chance
// match by one); groups within `min_group_fraction` (0.75) of the best group's accumulated score
// each give their best keyframe. Requires the map's vocabulary (MapData::SetVocabulary).
#pragma once

#include <set>
#include <vector>

#include "dynorb/map/map.h"

namespace dynorb {

struct PlaceQueryOptions {
  double min_common_fraction = 0.8;
  double min_group_fraction = 0.75;
  int group_covisibles = 10;
  double min_score = 0.0;  // keyframes scoring less are ignored (loop detection raises it)
};

// Best accumulated score first (ties: lower id); keyframes in `excluded` are neither returned
// nor counted.
std::vector<ScoredKeyframe> PlaceCandidates(const MapData& map, const BowVector& query,
                                            const std::set<KeyframeId>& excluded = {},
                                            const PlaceQueryOptions& options = {});

}  // namespace dynorb
