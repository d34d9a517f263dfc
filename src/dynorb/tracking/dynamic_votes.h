// Landmarks observed moving (issue #5: the dynamic label propagated to the map).
//
// A keypoint filter removes the keypoints of what moves before they are described, but landmarks
// made on an object before it moved (a person who stood still, a box before it was pushed, a
// keypoint the filter missed once) stay in the map, and a keypoint the filter misses later may
// match them. After a frame's pose is tracked, every local-map landmark that projects within
// `radius_px` of a keypoint the filter saw move (FilterOutput::moving_points) whose measured depth
// matches the landmark's is observed moving once. The tracker erases a landmark after repeated
// such observations (TrackerOptions::dynamic_votes_to_erase); a frame that matches it as a pose
// inlier without observing it moving clears its count.
//
// Why moving keypoints and not the filter's whole mask: masks reach past the movers (FAST's
// regions are grown on a 1/4-resolution depth map and dilated, detector boxes hold background), and
// votes from the mask alone erased as many static landmarks as dynamic ones (session 44,
// docs/fast_mode.md). The pixel lookups ignore lens distortion (TUM fr3 has none).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "dynorb/core/ids.h"
#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/map/landmark_summary.h"
#include "dynorb/map/map.h"
#include "dynorb/tracking/frame.h"

namespace dynorb {

struct DynamicVoteOptions {
  double radius_px = 8.0;  // A moving keypoint this close to the landmark's projection ...
  double band_m = 0.05;    // ... whose depth is within band_m + band_rel * z^2 of the landmark's.
  double band_rel = 0.01;
};

struct LandmarkSeenMoving {
  LandmarkId id = kNoLandmark;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // Its projection in the frame.
};

// A landmark the tracker erased, and where it came from (the oldest keyframe that still observed
// it), so that a benchmark can tell from ground-truth masks whether it was made on a moving object.
struct ErasedLandmark {
  LandmarkSeenMoving seen;
  LandmarkOrigin origin;
};

// Of `ids` / `points_in_world` (same length), those a frame at `cam_from_world` observes moving:
// a point of `moving_points` (pixels) lies within options.radius_px of the landmark's projection
// and the depth image `depth_m` (CV_32F metres, 0 = none) there is within the band of the
// landmark's depth. Moving points without depth vote for nothing.
std::vector<LandmarkSeenMoving> LandmarksSeenMoving(
    const std::vector<LandmarkId>& ids, const std::vector<Eigen::Vector3d>& points_in_world,
    const Rigid3d& cam_from_world, const PinholeCamera& camera,
    const std::vector<cv::Point2f>& moving_points, const cv::Mat& depth_m,
    const DynamicVoteOptions& options);

// Counts one frame's votes in the map: `frame`'s pose inliers that were not seen moving clear
// their landmark's count, each landmark of `seen` gets a vote, and those reaching
// `votes_to_erase` are erased (returned with their origin).
std::vector<ErasedLandmark> ApplyDynamicVotes(const Frame& frame,
                                              const std::vector<LandmarkSeenMoving>& seen,
                                              int votes_to_erase, MapData* map);

}  // namespace dynorb
