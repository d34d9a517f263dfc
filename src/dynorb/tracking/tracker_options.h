// Options of the tracker (defaults: ORB-SLAM2's RGB-D values).
#pragma once

#include <cstdint>

#include "dynorb/optimization/pose_optimizer.h"
#include "dynorb/tracking/dynamic_votes.h"
#include "dynorb/tracking/projection_search.h"

namespace dynorb {

struct TrackerOptions {
  int min_init_points = 500;               // Keypoints needed to initialise (ORB-SLAM2: N > 500) ...
  int min_init_depth_points = 100;         // ... of which this many with depth (they seed the map).
  double motion_radius_px = 7.0;           // Search radius (level 0) for motion-model tracking.
  double local_map_radius_factor = 3.0;    // Radius factor for local-map search.
  double relocalized_radius_factor = 5.0;  // Same, for the two frames after a relocalisation.
  int min_motion_matches = 20;             // Below: search again with twice the radius.
  int min_frame_inliers = 10;              // Inliers needed after motion / reference tracking.
  int min_local_map_inliers = 30;          // Inliers needed after local-map tracking.
  int min_local_map_inliers_after_reloc = 50;
  int max_local_keyframes = 80;
  int max_frames_between_keyframes = 30;   // Insert at least every fps frames (c1a).
  int min_frames_between_keyframes = 0;
  double reference_ratio = 0.75;           // Insert when tracking < ratio x reference matches.
  int close_tracked_max = 100;             // "Need close points": tracked close < this ...
  int close_untracked_min = 70;            // ... and untracked close > this.
  // Frames after a keyframe before "need close points" may ask for another (not in ORB-SLAM2,
  // where a busy mapper spaces them). Unrepeatable close keypoints (texture-poor desks, sensor
  // noise) otherwise keep the rule true and give a keyframe per frame, half of them culled again.
  int close_keyframe_min_frames = 5;
  // A keyframe for a view the keypoint filter keeps covering (0: off = ORB-SLAM2). When
  // max_frames_between_keyframes have passed since the last keyframe, the filter removed at least
  // this fraction of the frame's detected keypoints and more than close_untracked_min close
  // keypoints are unmatched, "need close points" holds even with many close points tracked: the
  // background the movers do not cover keeps the tracked count above the reference rule, and
  // the stretch would otherwise get no keyframe (sessions 30-32, docs/slam_core.md). Without a
  // keypoint filter (plain mode) the fraction is 0 and nothing changes.
  double filtered_keyframe_fraction = 0.15;
  // ... and only once the camera is at least this far (m) or turned at least this much (deg) from
  // its reference keyframe: a keyframe at the reference's viewpoint sees the same background the
  // movers leave (session 32: walking_static, a camera within ~2 cm / 1 deg, got worse with the
  // rule). Both 0: no motion condition.
  double filtered_keyframe_min_motion_m = 0.05;
  double filtered_keyframe_min_rotation_deg = 5.0;
  // A landmark seen by one keyframe and found in fewer frames than this is provisional in pose
  // optimisation (optimization/pose_optimizer.h): it must agree with the pose of the established
  // map before it counts. Keyframes turn every untracked close keypoint into a landmark — in a
  // dynamic scene the closest untracked keypoints are the movers. 0 disables.
  int provisional_min_found = 3;
  int new_close_points = 100;              // Landmarks created from depth per new keyframe.
  // When lost: first the keyframes place recognition finds (when the map has a vocabulary; at most
  // this many), then the most recent keyframes not tried yet, up to relocalization_candidates in
  // all.
  int relocalization_place_candidates = 10;
  int relocalization_candidates = 40;  // Keyframes tried when lost.
  // Motion prior on the camera centre (0: off = ORB-SLAM2). Every pose solve of a tracked frame
  // also weighs where a smoothed constant-velocity model puts the camera centre, with this
  // standard deviation (m); the velocity (m/s) is an exponential average of the tracked centres'
  // motion with this gain. Measured over 12 dynamic sequences and their twins (docs/results.md,
  // session 26): mean ATE -7 % (twins), -4 % (FAST), -7..-11 % (semantic, fused).
  double motion_prior_sigma_m = 0.004;
  double motion_prior_velocity_gain = 0.1;
  // A landmark observed moving this many times (dynamic_votes.h), with no pose-inlier match in
  // between that did not observe it moving, is erased from the map (0: never, the default).
  // Measured in session 44 and not adopted: at most half of the erased landmarks had been made on
  // a moving object, and the FAST mean ATE rose by up to 4 % (docs/fast_mode.md, "Session 44").
  int dynamic_votes_to_erase = 0;
  DynamicVoteOptions dynamic_votes;
  uint64_t seed = 0;                       // Seeds randomised steps (relocalisation RANSAC).
  PoseOptimizerOptions pose;
  MatcherOptions matcher;

  void Validate() const;  // Throws InputError.
};

}  // namespace dynorb
