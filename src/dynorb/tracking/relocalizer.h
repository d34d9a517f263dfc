// Relocalizer: recovers the pose of a frame when tracking is lost.
// Candidates are the most recent keyframes (place recognition with a vocabulary comes later).
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

 private:
  bool TryCandidate(const MapData& map, KeyframeId candidate, Frame* frame) const;

  RgbdSensor sensor_;
  TrackerOptions options_;
};

}  // namespace dynorb
