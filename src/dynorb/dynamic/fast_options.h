// FastOptions: every switch and threshold of the FAST dynamic mode (`dynorb run --mode fast`,
// YAML section `fast:`, docs/fast_mode.md). Defaults in the declaration; Validate() throws
// InputError. Value type.
#pragma once

#include <string>

namespace dynorb {

enum class CorrespondenceMethod { kOpticalFlow, kDescriptors };

struct FastOptions {
  // --- 1. Correspondences between the previous and the current frame.
  std::string correspondences = "flow";  // "flow" (pyramidal LK) or "descriptors" (BF Hamming)
  int lk_window_px = 21;                 // LK window side (px)
  int lk_levels = 1;                     // LK pyramid levels above the base image (session 48:
                                         // 1 instead of 3, same accuracy, the retracks -50 %)
  int lk_iterations = 20;                // LK iterations per level
  double lk_epsilon_px = 0.01;           // LK stops a point once its update is below this (px)
  double lk_fb_max_px = 1.0;             // forward-backward check: max return error (px)
  bool lk_fb_candidates_only = true;      // backward-track only points a cue flags moving (the
                                         // check keeps bad tracks from looking like movers)
  int lk_fb_levels = 1;                  // pyramid levels above the base image of the backward
                                         // check (capped at lk_levels; session 15: 1 instead of 3
                                         // gave the same labels, ~0.25 ms less per frame)
  int lk_max_points = 400;               // track at most this many keypoints, spread over the
                                         // image (0: all); the others are judged by regions
  bool lk_predict_initial = true;        // seed LK with the motion-model + depth prediction
  bool lk_seed_own_motion = true;        // ... with the filter's own last ego-motion when it has one
                                         // (one frame old; the tracker's is older when pipelined)
  double lk_base_first_px = 1.0;         // > 0 (with a prediction): LK on the base image first;
                                         // results farther than this from the prediction are
                                         // tracked again through the whole pyramid (0: off)
  int lk_base_shift_min_points = 20;     // > 0: on the analysis after a carried frame (whose
                                         // guess is two frames old), the base pass's median
                                         // offset from the guesses is removed before that test
                                         // and the retracks start from guess + offset; needs this
                                         // many converged points (0: off; session 51)
  bool lk_base_shift_always = false;     // ... on every analysis (session 51: worse ATE on
                                         // walking_rpy)
  int lk_base_window_px = 11;            // LK window of that first base-image pass (0: lk_window_px;
                                         // session 17: 11 px, a quarter of the 21 px window's area)
  double bf_best_fraction = 1.0 / 3.0;   // descriptors: best matches kept for estimating F
  int bf_max_distance = 80;              // descriptors: max Hamming distance of a match
  double bf_max_ratio = 0.8;             // descriptors: Lowe ratio best/second best (1: no test)
  // --- 2./3. Fundamental matrix (RANSAC) and epipolar distance.
  bool use_epipolar = true;          // epipolar cue on/off
  double f_ransac_px = 1.0;          // RANSAC inlier threshold for F (px)
  double f_confidence = 0.99;        // RANSAC confidence
  double epi_t1_px = 1.5;            // d <= t1: static
  double epi_t2_px = 30.0;           // d >= t2: mismatch (no evidence); t1 < d < t2: moving
  bool check_f_with_prediction = true;  // reject an F that disagrees with the ego-motion
  // --- 4. Flow direction vs the nearest static inlier.
  bool use_direction = true;          // direction cue on/off
  double direction_max_deg = 30.0;    // angle difference above this: moving
  double direction_min_flow_px = 2.0; // both flows must be at least this long to compare
  // --- 5. Flow-magnitude statistics.
  bool use_magnitude = true;          // magnitude cue on/off
  double magnitude_sigmas = 2.0;      // |m - mean| > k sigma: moving
  double magnitude_min_sigma_px = 0.5;  // below this sigma use the plain difference instead
  double magnitude_abs_diff_px = 2.0;   // plain difference from the mean that means moving
  // --- Beyond the report: rigid-warp residual against the (refined) camera motion.
  bool use_residual = true;           // ego-motion residual cue on/off
  bool refine_ego_motion = true;      // refine the motion-model prediction on tracked points
  bool ego_skip_previous_mask = true;  // points whose previous position lies in the previous
                                       // frame's dynamic regions do not vote for the ego-motion ...
  bool ego_previous_mask_always =
      true;                            // ... not only when the prediction was outvoted (session 23)
  bool ego_previous_removed = true;    // ... nor those landing within 2 px of a keypoint removed
                                       // there (session 23: a slow mover the prediction follows)
  double ego_skip_max_fraction = 0.8;  // ... unless they are more than this fraction of the tracks
                                       // (0.6 before session 21)
  double ego_skip_search_gate_px = 0.8;  // a prediction covering 60 % of the image at a scoring
                                         // gate at most this (px): no identity/RANSAC search
  bool ego_abandon_duplicates = true;    // a prediction whose first refit lands within 2 mm /
                                         // 1 mrad of a refined one is not refined further
  double ego_rigidity_ratio = 1.5;    // a prediction also wins when every hypothesis covering more
                                      // fits this many times more loosely (0: off)
  double residual_px = 1.2;           // reprojection residual above this: moving
  double residual_rel = 0.05;         // ... plus this fraction of the flow length
  double residual_mismatch_px = 40.0;  // residual above this: a wrong correspondence, no evidence
  bool use_depth = true;              // depth-consistency cue on/off
  double depth_abs_m = 0.03;          // depth change tolerance: abs + rel * z^2
  double depth_rel = 0.01;            // (Kinect-like noise grows with z^2)
  double max_depth_m = 8.0;           // ignore depth beyond this
  // --- Fusion of the cues into moving seeds.
  double weight_residual = 1.0;       // vote weights of each cue
  double weight_depth = 1.0;
  double weight_epipolar = 0.5;
  double weight_direction = 0.5;
  double weight_magnitude = 0.5;
  double seed_score = 1.0;            // a keypoint with score >= this is a moving seed
  bool residual_static_veto = false;  // the epipolar, direction and magnitude votes do not count
                                      // where the warp-residual cue says static (a near standing
                                      // object's larger flow; `--mode fast` sets it since
                                      // session 51, `--mode fused` since session 52)
  // --- Region growing on depth.
  bool use_region = true;             // grow seeds into depth segments
  int region_scale = 4;               // region grid: 1/region_scale resolution
  double region_edge_abs_m = 0.04;    // neighbour depth step allowed: abs + rel * z
  double region_edge_rel = 0.03;
  double region_band_m = 0.3;         // max depth distance from the seed's depth
  int region_min_seeds = 3;           // seeds needed (1 when supported by the suspect map; 2
                                      // before session 33)
  double region_max_static_ratio = 0.4;   // max static/(static+moving) tracked points in a region
  double region_min_coherence = 0.6;  // seeds of a region must move alike (|mean m| / mean |m|)
  double region_max_area = 0.8;       // max region area as a fraction of the image
  int region_dilate_px = 8;           // dilation of the final mask (full-resolution px; 6 before
                                      // session 24)
  // A keypoint of pyramid octave o also counts as in a region when its FAST circle (radius
  // 3·scale_factor^o full-resolution px) reaches farther than the dilation and the undilated
  // region lies within that radius: the corner is then partly the mover's outline. Checked as
  // the dilated mask within 3·scale_factor^o − region_dilate_px px (octaves 5–7 by default).
  bool region_octave_reach = false;
  // --- Temporal propagation.
  int suspect_frames = 5;             // a dynamic region stays suspect for this many frames
  double suspect_depth_m = 0.2;       // ... where the depth still matches the region's depth
  int track_history = 8;              // keypoint-track memory (frames)
  int track_min_moving = 3;           // a track seen moving this often (in history) is excluded
  // Lone seeds (session 24): most moving seeds and flagged tracks outside every region and the
  // suspect map are static (walking_rpy s8: 2558 of 2971), so such a "lone seed" is removed only
  // when its previous position lies within lone_seed_persistent_px of a keypoint flagged in the
  // previous frame (a mover flagged twice; noise rarely is; 0: never). remove_lone_seeds: every
  // lone seed is removed (the rule before session 24). A kept lone seed still counts as removed
  // for the next frame's ego-motion prior.
  bool remove_lone_seeds = false;
  double lone_seed_persistent_px = 4.0;
  // A keypoint flagged by the suspect map alone (no seed, track or region) is removed when its
  // cell was in a region at most this many frames ago (>= suspect_frames: always, the default;
  // 0: never). Measured in session 24 and not adopted: 1 loses a pushed box the suspect map holds.
  int lone_suspect_max_age = 30;
  // --- Analysis schedule (session 41). The cues run on every analyse_every-th frame; on the
  // frames between, only the suspect map is carried (warped by the tracker's motion prediction,
  // kept where the depth matches) and the keypoints in it, dilated by carry_reach_px, are removed;
  // such a frame still becomes the next frame's previous one (its LK pyramid is built), so every
  // analysis tracks across one frame. Flow correspondences only; needs use_region and
  // suspect_frames > 0. The track memory (track_min_moving) and a lone seed's persistence
  // (lone_seed_persistent_px) span consecutive analysed frames only: a frame between analyses
  // starts its keypoints without history, and flags only what it removed.
  int analyse_every = 1;
  double carry_reach_px = 8.0;
  // Quiet scenes (session 50): after quiet_min_analyses consecutive analysed frames that grew no
  // region, had no suspect cell left and removed at most quiet_max_removed keypoints, the next
  // quiet_analyse_every - 1 frames are carried (as above); then the streak starts again, so with
  // the defaults 2 / 2 the frames go analysed, analysed, carried, ... until an analysis is not
  // quiet. A mover entering a quiet scene is found up to quiet_analyse_every - 1 frames late.
  // 1: off. Applies only with flow correspondences, use_region and suspect_frames > 0 (what a
  // carried frame needs); otherwise every frame is analysed.
  int quiet_analyse_every = 1;
  int quiet_min_analyses = 2;
  int quiet_max_removed = 5;
  // --- Refill (SystemOptions::refill_filtered).
  // When a frame's removals reach this fraction of its keypoints (and it has a grown region),
  // the mask is taken to cover the movers (KeypointFilter::MaskCoversDetections): the System
  // detects again outside the mask and the removed keypoints and spends the whole budget on the
  // rest, which a mover filling half the view otherwise leaves a few keypoints. 0: never.
  double refill_min_removed_fraction = 0.0;
  uint64_t seed = 0;                  // RNG seed for RANSAC (cv::setRNGSeed)

  // Whether frames can be carried between analyses (analyse_every, quiet_analyse_every): the LK
  // pyramid and the suspect map they need.
  bool CanCarry() const {
    return method() == CorrespondenceMethod::kOpticalFlow && use_region && suspect_frames > 0;
  }
  CorrespondenceMethod method() const {
    return correspondences == "descriptors" ? CorrespondenceMethod::kDescriptors
                                            : CorrespondenceMethod::kOpticalFlow;
  }
  void Validate() const;  // throws InputError
};

}  // namespace dynorb
