// FastFilter: the deep-learning-free, CPU-only moving-keypoint filter (`dynorb run --mode fast`,
// docs/fast_mode.md). Per frame, between the previous and the current frame:
//  1. correspondences of the current keypoints (LK optical flow with a forward–backward check, or
//     brute-force ORB descriptor matching) — the SLAM extractor's keypoints, no second detection;
//  2. ego-motion: the motion-model prediction refined on the tracked points with depth
//     (motion_ego.h) — robust to a mover that dominates the image;
//  3. fundamental matrix by RANSAC on the correspondences (checked against the ego-motion and
//     replaced by the ego-motion's F when it locked onto a mover);
//  4. cues (fast_cues.h): epipolar distance (t1 < d < t2), flow direction vs the nearest static
//     inlier, flow-magnitude statistics, rigid-warp residual and depth consistency; a weighted
//     vote makes moving seeds;
//  5. temporal memory: keypoint tracks seen moving repeatedly are excluded, and recent dynamic
//     regions stay suspect for a few frames (fast_region.h);
//  6. seeds grown into depth regions (fast_region.h); every keypoint in a dynamic region, every
//     seed and every flagged track is removed (keep = false).
// With FastOptions::analyse_every N > 1 the steps run on every Nth frame only; the frames between
// carry the suspect map by the tracker's motion prediction and remove what lies in it
// (CarryForward: ~1.4 ms instead of ~6; session 41, docs/fast_mode.md). With
// FastOptions::quiet_analyse_every N > 1 the same carry takes N - 1 frames after every two
// consecutive quiet analyses (no region, no suspect cell, few removals; session 50).
// Code: fast_filter.cc (Filter; correspondences, ego-motion, warp residual, F),
// fast_filter_classify.cc (cues and fusion, track memory, suspect map, regions, removal, overlay).
// Owns the previous frame's LK pyramid, keypoints, descriptors (descriptor mode), depth, track
// memory and suspect map. Called from the tracking thread only (KeypointFilter contract);
// deterministic (fixed RANSAC seeds).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/dynamic/fast_correspondence.h"
#include "dynorb/dynamic/fast_options.h"
#include "dynorb/dynamic/fast_region.h"
#include "dynorb/dynamic/keypoint_filter.h"
#include "dynorb/features/orb_extractor.h"

namespace dynorb {

// Per-stage wall time of one frame (ms).
struct FastTiming {
  double flow_ms = 0.0;         // correspondences (LK pyramid + tracking, or describe + match)
  double ego_ms = 0.0;          // ego-motion refinement
  double fundamental_ms = 0.0;  // F by RANSAC + check
  double cues_ms = 0.0;         // point-wise cues and fusion (classification)
  double region_ms = 0.0;       // temporal propagation + region growing
  double overlay_ms = 0.0;      // drawing (only with want_overlay)
  double total_ms = 0.0;
  FastTiming& operator+=(const FastTiming& o);
};

// Bits of FastFilter::cue_bits(): which cue voted "moving" for a keypoint.
enum FastCue : uint16_t {
  kCueEpipolar = 1 << 0,
  kCueDirection = 1 << 1,
  kCueMagnitude = 1 << 2,
  kCueResidual = 1 << 3,
  kCueDepth = 1 << 4,
  kCueSeed = 1 << 5,       // fused score >= seed_score
  kCueTrack = 1 << 6,      // a track flagged by its history
  kCueSuspect = 1 << 7,    // inside the temporal suspect map
  kCueRegion = 1 << 8,     // inside a grown dynamic region
  kCueTracked = 1 << 9,    // had a correspondence (not a vote)
  kCueMismatch = 1 << 10,  // epipolar distance >= t2 or warp residual >= residual_mismatch_px
};

// Per-frame diagnostics.
struct FastFrameInfo {
  bool has_previous = false;
  bool ego_ok = false;
  int ego_seed = -1;           // index of the accepted motion seed (tracker first, own chain), -1: RANSAC (see motion_ego.h)
  bool f_ok = false;           // RANSAC F estimated
  bool f_replaced = false;     // F disagreed with the ego-motion and was replaced
  int num_keypoints = 0, num_tracked = 0, num_seeds = 0, num_removed = 0, num_regions = 0;
  int num_retracked = 0;  // flow: points tracked again through the pyramid (lk_base_first_px)
};

class FastFilter : public KeypointFilter {
 public:
  // orb: the SLAM extractor's options (descriptor mode re-describes the detected keypoints).
  FastFilter(const FastOptions& options, const PinholeCamera& camera, const OrbOptions& orb = OrbOptions());

  std::string name() const override { return "fast"; }
  FilterOutput Filter(const FilterInput& input) override;

  std::vector<std::pair<std::string, double>> StageTimings() const override;
  // One entry per FastCue bit except kCueTracked ("epipolar", "direction", ..., "region").
  std::vector<std::pair<std::string, std::vector<bool>>> CueFlags() const override;
  // True after a frame whose grown regions removed at least
  // FastOptions::refill_min_removed_fraction of its keypoints (never when that is 0).
  bool MaskCoversDetections() const override;
  const FastTiming& timing() const { return timing_; }              // last frame
  const FastTiming& total_timing() const { return total_timing_; }  // sum over frames
  int frames() const { return frames_; }
  const std::vector<uint16_t>& cue_bits() const { return cue_bits_; }  // last frame, per keypoint
  const FastFrameInfo& info() const { return info_; }
  // Last frame, per keypoint: position in the previous frame (when tracked) and the rigid-warp
  // residual in px (-1: not computed).
  const std::vector<cv::Point2f>& previous_positions() const { return last_p1_; }
  const std::vector<float>& residuals_px() const { return last_residual_; }

 private:
  struct FrameWork;  // one frame's intermediate results (fast_filter_frame.h)
  // The stages of Filter(), in order (numbers as in the header comment).
  void FindCorrespondences(FrameWork* w);                      // 1.
  void EstimateMotion(FrameWork* w);                           // 2.
  void ComputeWarpResidual(FrameWork* w) const;                // rigid-warp residual, depth cue
  void EstimateFundamental(FrameWork* w);                      // 3.
  void Classify(FrameWork* w);                                 // 4. and the track memory of 5.
  void GrowRegionsAndRemove(FrameWork* w, FilterOutput* out);  // 5. suspect map, 6.
  // A frame between analyses (FastOptions::analyse_every): the carried suspect map's removals.
  FilterOutput CarryForward(const FilterInput& input);
  // previous_mask_ for the next frame's ego-motion prior: `mask` (may be empty) plus, with
  // ego_previous_removed, 2 px disks at previous_flagged_.
  void KeepPreviousMask(const cv::Mat& mask, cv::Size size);
  cv::Mat DrawOverlay(const FilterInput& input, const std::vector<cv::Point2f>& p1,
                      const std::vector<cv::Point2f>& p2, const cv::Mat& mask) const;

  FastOptions options_;
  LkOptions lk_;  // the LK part of options_
  PinholeCamera camera_;
  OrbExtractor extractor_;
  // Previous frame.
  bool has_previous_ = false;
  std::vector<cv::Mat> previous_pyramid_;
  std::vector<cv::KeyPoint> previous_keypoints_;
  std::vector<cv::Point2f> previous_points_;
  // The previous frame's keypoints flagged by any cue (removed or kept): lone-seed persistence
  // and, with ego_previous_removed, the ego-motion prior.
  std::vector<cv::Point2f> previous_flagged_;
  std::vector<uint16_t> previous_history_;
  cv::Mat previous_descriptors_;
  cv::Mat previous_depth_;
  cv::Mat previous_mask_;  // the previous frame's dynamic regions (empty: none) and, with
                           // ego_previous_removed, 2 px disks at the keypoints it removed
  SuspectMap suspect_;
  std::optional<Rigid3d> own_prev_from_cur_;  // last ego-motion (constant-velocity seed)
  // Analysis schedule (FastOptions::analyse_every): frames since the last analysed one; whether
  // an analysis has judged a frame (had a previous one).
  int frames_since_analysis_ = 0;
  bool judged_once_ = false;
  // Analysed frames in a row that were quiet (FastOptions::quiet_analyse_every).
  int quiet_analyses_ = 0;
  int AnalysisInterval() const;  // the current analyse_every (quiet schedule applied)
  bool LastAnalysisQuiet() const;
  // Diagnostics.
  FastTiming timing_, total_timing_;
  int frames_ = 0;
  std::vector<uint16_t> cue_bits_;
  std::vector<cv::Point2f> last_p1_;
  std::vector<float> last_residual_;
  FastFrameInfo info_;
};

}  // namespace dynorb
