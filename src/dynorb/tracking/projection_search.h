// Matching the current frame's keypoints to landmarks (ORB-SLAM2's ORBmatcher, our version).
//
// - SearchFromLastFrame: project the last frame's matched landmarks with the predicted pose and
//   look for the best descriptor in a radius scaled by the keypoint's pyramid level.
// - SearchLocalMap: project the local map's landmarks that are in the frustum (in front, inside
//   the image, within the landmark's scale-invariance distance range, viewing angle within 60°
//   of its mean viewing direction) and match with a ratio test at the predicted level.
// - MatchByDescriptor: brute-force matching of the frame against a keyframe's landmarks (no
//   prior pose), for reference-keyframe tracking and relocalisation.
// All use an orientation-consistency histogram (30 bins; keep the three dominant bins) to reject
// matches whose keypoint-angle change disagrees with the majority. Pure functions, thread-safe.
#pragma once

#include <vector>

#include "dynorb/map/map.h"
#include "dynorb/map/match_rules.h"
#include "dynorb/tracking/frame.h"
#include "dynorb/tracking/local_map.h"

namespace dynorb {

struct MatcherOptions {
  int max_distance = 100;         // ORB-SLAM TH_HIGH.
  int strict_max_distance = 50;   // ORB-SLAM TH_LOW (fusion, triangulation).
  double ratio = 0.8;             // Best / second-best ratio (local map search).
  double brute_force_ratio = 0.7; // Ratio for MatchByDescriptor.
  bool check_orientation = true;
};

// Returns the number of new matches written into `current` (keypoints already matched are kept).
int SearchFromLastFrame(Frame* current, const Frame& last, const RgbdSensor& sensor, double radius_px,
                        const MatcherOptions& options = {});

// `visible` (optional) receives the ids of landmarks predicted to be visible (for statistics).
int SearchLocalMap(Frame* current, const LocalMap& local, const RgbdSensor& sensor, double radius_factor,
                   const MatcherOptions& options = {}, std::vector<LandmarkId>* visible = nullptr);

// Matches of frame keypoints to the landmarks of `keyframe`: pairs (frame keypoint, landmark id).
struct FrameLandmarkMatch {
  int keypoint = -1;
  LandmarkId landmark = kNoLandmark;
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
};
std::vector<FrameLandmarkMatch> MatchByDescriptor(const FrameFeatures& frame, const Keyframe& keyframe,
                                                  const MapData& map, const MatcherOptions& options = {});

}  // namespace dynorb
