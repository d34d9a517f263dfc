// Tracker: estimates the pose of each RGB-D frame against the map (ORB-SLAM2's Tracking).
//
// State machine: kNotInitialized -> (first frame with >= min_init_points keypoints, enough with depth:
// first keyframe, world = that camera) -> kOk <-> kLost. In kOk: constant-velocity motion model
// (projection search from the last frame), falling back to brute-force matching against the
// reference keyframe; then the local map is projected and the pose refined (pose-only BA with
// chi^2 outlier rejection); finally the keyframe decision. In kLost: relocalisation (descriptor
// matching against recent keyframes, PnP RANSAC, pose-only BA). A lost frame never aborts a run.
//
// ProcessOne() knows nothing about threads. It reads the Map through snapshots and writes only
// when it creates a keyframe (plus visibility counters); it holds Map::BeginFrame() throughout, so
// a loop correction or global-BA commit (Map::Correct) lands between frames, never during one.
// Not thread-safe itself: one caller.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "dynorb/map/map.h"
#include "dynorb/tracking/centre_motion_model.h"
#include "dynorb/tracking/dynamic_votes.h"
#include "dynorb/tracking/frame.h"
#include "dynorb/tracking/tracker_options.h"

namespace dynorb {

enum class TrackingState { kNotInitialized, kOk, kLost };
const char* ToString(TrackingState state);

struct TrackingResult {
  TrackingState state = TrackingState::kNotInitialized;
  bool pose_valid = false;
  Rigid3d cam_from_world;
  KeyframeId reference_keyframe = kNoKeyframe;
  Rigid3d cam_from_reference;  // When pose_valid: the pose relative to reference_keyframe.
  uint64_t correction_epoch = 0;  // The map's correction epoch cam_from_world is expressed in.
  KeyframeId new_keyframe = kNoKeyframe;  // Set when this frame became a keyframe.
  int num_inliers = 0;
  bool relocalized = false;
  double local_map_ms = 0.0;               // Time spent on local-map tracking.
  std::vector<int> inlier_keypoints;       // Keypoints the final pose rests on (frame feature indices).
  std::vector<int> new_landmark_keypoints;  // Keypoints that became new landmarks (new keyframe).
  int dynamic_votes = 0;                    // Local landmarks observed moving (dynamic_votes.h).
  std::vector<ErasedLandmark> erased_as_dynamic;  // Of those, the ones erased (enough votes).
};

class Tracker {
 public:
  Tracker(const RgbdSensor& sensor, const TrackerOptions& options, Map* map);

  // Tracks one frame. `mapper_idle`: the local mapper has no queued keyframes (always true in
  // sequential mode).
  TrackingResult ProcessOne(Frame frame, bool mapper_idle);

  TrackingState state() const { return state_; }
  const Frame& last_frame() const { return last_frame_; }

 private:
  bool Initialize(Frame* frame, std::vector<int>* created);
  bool TrackWithMotionModel(Frame* frame);
  bool TrackReferenceKeyframe(Frame* frame);
  bool Relocalize(Frame* frame);
  // Also finds the local landmarks observed moving and erases the repeat offenders
  // (TrackerOptions::dynamic_votes_to_erase) into `result`.
  bool TrackLocalMap(Frame* frame, int* inliers, TrackingResult* result);
  int OptimizeAndCount(Frame* frame, bool drop_outliers);
  bool NeedNewKeyframe(const Frame& frame, bool mapper_idle) const;
  // The covered-view rule's motion condition (TrackerOptions::filtered_keyframe_min_motion_m).
  bool MovedFromReference(const Frame& frame,
                          const std::optional<Rigid3d>& reference_cam_from_world) const;
  // Inserts the frame as a keyframe and creates landmarks from its depth: every keypoint with depth
  // (first keyframe) or the nearest ones until new_close_points beyond th_depth (ORB-SLAM2).
  // `created` (optional) receives the indices of the keypoints that became new landmarks.
  // erased_as_dynamic: landmarks this frame's dynamic votes erased (their keypoints get none).
  KeyframeId CreateKeyframe(Frame* frame, bool all_depth_points,
                            std::vector<int>* created = nullptr,
                            const std::vector<ErasedLandmark>* erased_as_dynamic = nullptr);
  void RefreshLandmarkPoints(Frame* frame) const;
  // Sets centre_prior_ for `frame` (or clears it) / updates the centre velocity after it was
  // tracked.
  void PredictCentre(const Frame& frame, bool just_relocalized);
  void UpdateCentreVelocity(const Frame& frame, bool relocalized);

  RgbdSensor sensor_;
  TrackerOptions options_;
  Map* map_;
  TrackingState state_ = TrackingState::kNotInitialized;
  Frame last_frame_;
  std::optional<Rigid3d> velocity_;  // current_from_last (cam_from_cam).
  // Motion prior (options_.motion_prior_sigma_m > 0): the centre's motion model and the prior of
  // the frame being tracked.
  CentreMotionModel centre_model_;
  std::optional<CentrePrior> centre_prior_;
  // The last frame's pose relative to its reference keyframe, so that the prior follows the
  // keyframe when local BA moves it (ORB-SLAM2's UpdateLastFrame), and the last frame follows a
  // loop correction.
  KeyframeId last_reference_keyframe_ = kNoKeyframe;
  Rigid3d last_from_reference_;
  Rigid3d LastFramePoseNow() const;
  // After a correction of the whole map (MapData::correction_epoch, loop closing) the last frame
  // follows its reference keyframe, so the motion model predicts in the corrected map.
  void ReanchorAfterCorrection();
  uint64_t seen_correction_epoch_ = 0;
  KeyframeId reference_keyframe_ = kNoKeyframe;
  FrameId last_keyframe_frame_ = 0;
  FrameId last_relocalization_frame_ = 0;
  bool ever_relocalized_ = false;
};

}  // namespace dynorb
