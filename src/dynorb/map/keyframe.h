// Keyframe: a frame kept in the map, with its pose, measurements and graph edges.
// Owned by MapData; refers to landmarks and keyframes by id.
#pragma once

#include <map>
#include <memory>
#include <set>
#include <vector>

#include "dynorb/core/ids.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/map/frame_features.h"
#include "dynorb/place_recognition/vocabulary.h"

namespace dynorb {

struct Keyframe {
  KeyframeId id = kNoKeyframe;
  FrameId frame_id = 0;
  double timestamp_s = 0.0;
  Rigid3d cam_from_world;
  std::shared_ptr<const FrameFeatures> features;
  std::vector<LandmarkId> landmarks;              // Per keypoint; kNoLandmark if none.
  std::map<KeyframeId, int> covisibility;         // Keyframe -> number of shared landmarks.
  std::vector<KeyframeId> ordered_covisibles;     // By weight, descending (ties: by id).
  KeyframeId parent = kNoKeyframe;                // Spanning tree.
  std::set<KeyframeId> children;
  BowVector bow;  // Bag of words (MapData::AddKeyframe, when the map has a vocabulary).
  bool keep = false;  // Never culled (an end of a loop edge: the pose graph needs it later).

  Eigen::Vector3d CameraCenterInWorld() const { return cam_from_world.Inverse().translation; }
};

}  // namespace dynorb
