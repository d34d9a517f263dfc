// Relocalizer: recovers the pose of a frame when tracking is lost.
// Candidates: the keyframes place recognition finds for the frame's bag of words
// (map/place_candidates.h; when the map has a vocabulary), then the most recent keyframes.
// For each: brute-force descriptor matches to its landmarks (>= 15), PnP RANSAC (OpenCV EPnP
// inside RANSAC), pose-only BA on the RANSAC inliers; with fewer than 50 inliers, the candidate's
// local map is projected for more matches and the pose refined again. Success: >= 50 inliers.
// Reads the map under its read lock; stateless otherwise.
#pragma once

#include "dynorb/map/map.h"
#include "dynorb/tracking/frame.h"
#include "dynorb/tracking/tracker_options.h"

namespace dynorb {

class Relocalizer {
 public:
  Relocalizer(const RgbdSensor& sensor, const TrackerOptions& options) : sensor_(sensor), options_(options) {}
  // On success fills frame->cam_from_world, matches and reference_keyframe; returns true.
  bool Relocalize(const Map& map, Frame* frame) const;
  // One candidate (also loop closing's geometric check): the frame's pose from its matches to the
  // candidate's landmarks and its local map; true with >= 50 inliers (frame filled as above).
  bool LocalizeAgainst(const MapData& map, KeyframeId candidate, Frame* frame) const;

 private:
  // Keyframes to try, in order (TrackerOptions::relocalization_place_candidates / _candidates).
  std::vector<KeyframeId> Candidates(const MapData& map, const FrameFeatures& features) const;

  RgbdSensor sensor_;
  TrackerOptions options_;
};

}  // namespace dynorb
