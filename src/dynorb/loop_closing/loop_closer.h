// LoopCloser: detects that the camera is back at a place mapped long ago and removes the drift
// accumulated since (ORB-SLAM2's LoopClosing, in SE(3): an RGB-D map has metric scale).
//
// ProcessOne(keyframe), after the local mapper processed it:
// 1. detection: keyframes that show the same place (map/place_candidates.h) but are not
//    covisible with it, scoring at least as high as its least similar covisible keyframe; a
//    candidate counts once its group (it and its covisibles) has been found for `consistency`
//    consecutive keyframes;
// 2. verification: the keyframe is localised against the candidate's landmarks and local map as
//    in relocalisation (descriptor matches, EPnP RANSAC, pose-only BA, >= 50 inliers), and that
//    pose must explain the loop side's local map (min_agreement of its landmarks in view found);
// 3. correction: the keyframe and its covisibles move rigidly to the verified pose (their landmarks
//    with them); the loop's matches and the neighbourhood's duplicates are fused; the essential
//    graph (spanning tree, strong covisibility edges with old relative poses, loop edges with
//    corrected ones) is optimised with the loop keyframe fixed (optimization/pose_graph.h), and
//    every landmark follows its reference keyframe. The map's correction epoch is bumped so the
//    tracker re-anchors its last frame.
// 4. global bundle adjustment (global_bundle_adjustment.h): inline, or with global_ba_thread
//    (parallel mode) on a thread of its own that a newer loop stops.
// Runs on the mapper's thread (parallel mode) or inline (sequential: deterministic).
#pragma once

#include <atomic>
#include <mutex>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "dynorb/core/background_error.h"
#include "dynorb/loop_closing/global_bundle_adjustment.h"
#include "dynorb/map/map.h"
#include "dynorb/mapping/mapper_options.h"
#include "dynorb/tracking/relocalizer.h"

namespace dynorb {

struct LoopClosingOptions {
  bool enabled = true;
  int min_keyframes = 10;          // no loop in a map with fewer keyframes
  int min_keyframes_between = 10;  // keyframe ids after a closed loop before the next
  int consistency = 3;             // consecutive keyframes whose candidates must agree
  int strong_covisibility = 100;   // covisibility edges of the essential graph (shared landmarks)
  int pose_graph_iterations = 20;
  // The verified pose must explain the loop side's map, not only the matches it rests on: of the
  // landmarks of the loop keyframe's local map predicted in view, at least this fraction must be
  // found in the keyframe (a person who walked past the old place again gives a pose that fits
  // the person's landmarks and none of the room's).
  double min_agreement = 0.1;
  bool global_ba = true;  // refine the whole map after each loop correction
  // Levenberg-Marquardt iterations of the global BA after its robust stage (which has the local
  // BA's first_iterations) excluded the outliers.
  int global_ba_iterations = 10;
  // Parallel run mode only (sequential mode always runs it inline): the global BA on a thread of
  // its own, as ORB-SLAM2 does, so that local mapping goes on during it; otherwise it blocks the
  // mapper's thread for its duration (0.15-0.7 s in a room-sized map). Off by default: on this
  // benchmark's loops the thread's variant was less accurate (docs/loop_closing.md).
  bool global_ba_thread = false;

  void Validate() const;  // Throws InputError.
};

struct LoopStepStats {
  KeyframeId keyframe = kNoKeyframe;
  bool detected = false;  // a consistent candidate existed
  bool closed = false;    // verified and corrected
  KeyframeId loop_keyframe = kNoKeyframe;
  int inliers = 0;
  double agreement = 0.0;  // of the best verified candidate (LoopClosingOptions::min_agreement)
  int fused = 0;
  double correction_m = 0.0;  // how far the verified pose moved the keyframe's camera centre
  double correction_deg = 0.0;
  double ms = 0.0;
};

class LoopCloser {
 public:
  LoopCloser(const RgbdSensor& sensor, const TrackerOptions& tracker_options,
             const LocalMapperOptions& mapper_options, const LoopClosingOptions& options, Map* map);

  ~LoopCloser();  // Waits for a global BA in the background to finish.
  LoopCloser(const LoopCloser&) = delete;
  LoopCloser& operator=(const LoopCloser&) = delete;

  LoopStepStats ProcessOne(KeyframeId keyframe);
  // Blocks until a global BA in the background (if any) has committed or given up; then
  // rethrows the exception a background global BA ended with, if one did (on every call).
  void WaitForGlobalBa();
  // The same without the rethrow.
  void JoinGlobalBa();
  // Rethrows the exception a background global BA ended with, if one did (without waiting).
  void RethrowGlobalBaError() const { global_ba_error_.Rethrow(); }
  std::vector<GlobalBaStats> global_ba_stats() const;

 private:
  struct Group {
    std::set<KeyframeId> keyframes;
    int consistency = 0;
  };
  std::vector<KeyframeId> Detect(const MapData& map, KeyframeId keyframe);
  // Found / predicted landmarks of the verified frame's local map (the loop side) at its pose.
  double Agreement(const MapData& map, const Frame& verified) const;
  void Correct(MapData* map, KeyframeId keyframe, KeyframeId loop_keyframe, const Frame& verified,
               LoopStepStats* stats);

  void StartGlobalBa();
  void StopGlobalBa();  // Stops a global BA in the background and waits for it.

  RgbdSensor sensor_;
  TrackerOptions tracker_options_;
  LocalMapperOptions mapper_options_;
  LoopClosingOptions options_;
  Map* map_;
  Relocalizer relocalizer_;
  std::vector<Group> groups_;
  KeyframeId last_loop_keyframe_ = kNoKeyframe;
  std::set<std::pair<KeyframeId, KeyframeId>>
      loop_edges_;  // (lower id, higher id), kept for later loops
  std::thread global_ba_thread_;
  BackgroundError global_ba_error_;  // The background global BA's exception (std::thread's
                                     // would end the process).
  std::atomic<bool> stop_global_ba_{false};
  mutable std::mutex global_ba_mutex_;  // guards global_ba_stats_
  std::vector<GlobalBaStats> global_ba_stats_;
};

}  // namespace dynorb
