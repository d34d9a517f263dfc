// `dynorb run --mode fast`: the deep-learning-free geometric moving-keypoint filter
// (src/dynorb/dynamic/fast_filter.h, docs/fast_mode.md), configured by the YAML section `fast:`.
#include "mode_fast.h"

#include <memory>

#include "dynorb/dynamic/fast_filter.h"

namespace dynorb {

void FastModeFactory::BindConfig(ConfigSchema* schema) {
  FastOptions& o = options_;
  schema->Section("fast", "FAST dynamic mode: geometric moving-object cues (docs/fast_mode.md)")
      .Add("correspondences", &o.correspondences,
           "flow (pyramidal LK + forward-backward) or descriptors (BF Hamming)")
      .Add("lk_window_px", &o.lk_window_px, "LK window side (px, odd)")
      .Add("lk_levels", &o.lk_levels, "LK pyramid levels above the base image")
      .Add("lk_iterations", &o.lk_iterations, "LK iterations per level")
      .Add("lk_epsilon_px", &o.lk_epsilon_px, "LK stops a point once its update is below this (px)")
      .Add("lk_fb_max_px", &o.lk_fb_max_px, "forward-backward check: max return error (px)")
      .Add("lk_fb_candidates_only", &o.lk_fb_candidates_only,
           "forward-backward check only for points a cue flags moving (faster; tracks that fail it "
           "unseen still feed the ego-motion and F, which are robust to them)")
      .Add("lk_max_points", &o.lk_max_points,
           "track at most this many keypoints, spread over the image (0: all)")
      .Add("lk_predict_initial", &o.lk_predict_initial,
           "seed LK with the motion-model + depth prediction")
      .Add("lk_seed_own_motion", &o.lk_seed_own_motion,
           "seed LK with the filter's own last ego-motion when it has one (one frame old; the "
           "tracker's prediction is older when pipelined)")
      .Add(
          "lk_fb_levels", &o.lk_fb_levels,
          "pyramid levels above the base image of the forward-backward check (capped at lk_levels)")
      .Add(
          "lk_base_first_px", &o.lk_base_first_px,
          "with a prediction: LK on the base image first, points ending farther than this from the "
          "prediction tracked again through the whole pyramid (px; 0: whole pyramid for all)")
      .Add("lk_base_shift_min_points", &o.lk_base_shift_min_points,
           "with lk_base_first_px, on the analysis after a carried frame: the base pass's median "
           "offset from the predictions is removed before that test and the retracks start from "
           "prediction + offset, when at least this many points converged (0: off)")
      .Add("lk_base_shift_always", &o.lk_base_shift_always,
           "lk_base_shift_min_points on every analysis, not only after a carried frame")
      .Add("lk_base_window_px", &o.lk_base_window_px,
           "LK window of the first base-image pass (px, odd, <= lk_window_px; 0: lk_window_px)")
      .Add("ego_skip_previous_mask", &o.ego_skip_previous_mask,
           "tracked points whose previous position lies in the previous frame's dynamic regions do "
           "not vote for the ego-motion (a mover that dominates the view cannot capture it)")
      .Add("ego_previous_mask_always", &o.ego_previous_mask_always,
           "ego-motion: the points in the previous frame's dynamic regions never vote (false: "
           "only when the prediction was outvoted)")
      .Add("ego_previous_removed", &o.ego_previous_removed,
           "ego-motion: the points landing within 2 px of a keypoint the previous frame removed "
           "do not vote either (a slow mover the prediction partly follows cannot pull the fit)")
      .Add("ego_skip_max_fraction", &o.ego_skip_max_fraction,
           "... unless they are more than this fraction of the tracked points (then all vote)")
      .Add("bf_best_fraction", &o.bf_best_fraction,
           "descriptors: fraction of best matches used for F")
      .Add("bf_max_distance", &o.bf_max_distance, "descriptors: max Hamming distance of a match")
      .Add("bf_max_ratio", &o.bf_max_ratio,
           "descriptors: Lowe ratio test, best/second best (1: off)")
      .Add("use_epipolar", &o.use_epipolar, "epipolar-distance cue")
      .Add("f_ransac_px", &o.f_ransac_px, "RANSAC inlier threshold for F (px)")
      .Add("f_confidence", &o.f_confidence, "RANSAC confidence for F")
      .Add("epi_t1_px", &o.epi_t1_px, "epipolar distance <= t1: static")
      .Add("epi_t2_px", &o.epi_t2_px, "epipolar distance >= t2: mismatch (no evidence)")
      .Add("check_f_with_prediction", &o.check_f_with_prediction,
           "replace an F that disagrees with the ego-motion")
      .Add("use_direction", &o.use_direction, "flow-direction cue (vs nearest static inlier)")
      .Add("direction_max_deg", &o.direction_max_deg, "angle difference above this: moving")
      .Add("direction_min_flow_px", &o.direction_min_flow_px,
           "min flow length to compare directions")
      .Add("use_magnitude", &o.use_magnitude, "flow-magnitude statistics cue")
      .Add("magnitude_sigmas", &o.magnitude_sigmas, "|m - mean| > k sigma: moving")
      .Add("magnitude_min_sigma_px", &o.magnitude_min_sigma_px,
           "below this sigma the plain difference decides")
      .Add("magnitude_abs_diff_px", &o.magnitude_abs_diff_px,
           "plain difference from the mean meaning moving")
      .Add("use_residual", &o.use_residual, "rigid-warp residual cue (ego-motion + depth)")
      .Add("refine_ego_motion", &o.refine_ego_motion,
           "refine the motion-model prediction on tracked points")
      .Add("ego_skip_search_gate_px", &o.ego_skip_search_gate_px,
           "ego-motion: a prediction covering 60 % of the image at a scoring gate of at most this "
           "(px) skips the camera-at-rest and RANSAC hypotheses")
      .Add("ego_abandon_duplicates", &o.ego_abandon_duplicates,
           "ego-motion: a prediction whose first refit lands within 2 mm / 1 mrad of a refined "
           "hypothesis is dropped (it would refine to the same pose)")
      .Add("ego_rigidity_ratio", &o.ego_rigidity_ratio,
           "ego-motion: a prediction also wins when every hypothesis covering more of the image "
           "fits this many times more loosely (a walking person fits a rigid motion loosely; 0: "
           "off)")
      .Add("residual_px", &o.residual_px,
           "warp residual above this (+ residual_rel * flow): moving")
      .Add("residual_rel", &o.residual_rel, "fraction of the flow length added to residual_px")
      .Add("residual_mismatch_px", &o.residual_mismatch_px,
           "warp residual above this: a wrong correspondence, no evidence")
      .Add("use_depth", &o.use_depth, "depth-consistency cue")
      .Add("depth_abs_m", &o.depth_abs_m, "depth tolerance: abs + rel * z^2 (m)")
      .Add("depth_rel", &o.depth_rel, "depth tolerance: rel (1/m)")
      .Add("max_depth_m", &o.max_depth_m, "ignore depth beyond this (m)")
      .Add("weight_residual", &o.weight_residual, "vote weight of the residual cue")
      .Add("weight_depth", &o.weight_depth, "vote weight of the depth cue")
      .Add("weight_epipolar", &o.weight_epipolar, "vote weight of the epipolar cue")
      .Add("weight_direction", &o.weight_direction, "vote weight of the direction cue")
      .Add("weight_magnitude", &o.weight_magnitude, "vote weight of the magnitude cue")
      .Add("seed_score", &o.seed_score, "fused score making a moving seed")
      .Add("residual_static_veto", &o.residual_static_veto,
           "the epipolar, direction and magnitude votes do not count where the warp-residual cue "
           "says static")
      .Add("use_region", &o.use_region, "grow seeds into depth regions")
      .Add("region_scale", &o.region_scale, "region grid is 1/region_scale of the image")
      .Add("region_edge_abs_m", &o.region_edge_abs_m, "neighbour depth step allowed: abs (m)")
      .Add("region_edge_rel", &o.region_edge_rel, "neighbour depth step allowed: rel * z")
      .Add("region_band_m", &o.region_band_m, "max depth distance from the seed (m)")
      .Add("region_min_seeds", &o.region_min_seeds, "seeds needed for a dynamic region")
      .Add("region_max_static_ratio", &o.region_max_static_ratio,
           "max static/(static+seed) points in a region")
      .Add("region_min_coherence", &o.region_min_coherence,
           "min agreement of the seeds' own motions")
      .Add("region_max_area", &o.region_max_area, "max region area (fraction of the image)")
      .Add("region_dilate_px", &o.region_dilate_px, "dilation of the dynamic mask (px)")
      .Add("region_octave_reach", &o.region_octave_reach,
           "a keypoint of octave o is in a region when the mask is within 3*scale_factor^o - "
           "region_dilate_px px (its FAST circle reaches past the dilation)")
      .Add("analyse_every", &o.analyse_every,
           "run the cues on every Nth frame; between, only the suspect map is carried by the "
           "motion prediction (1: every frame; flow correspondences only)")
      .Add("quiet_analyse_every", &o.quiet_analyse_every,
           "after quiet_min_analyses consecutive quiet analyses (no region, no suspect cell, at "
           "most quiet_max_removed keypoints removed) carry the next N - 1 frames instead of "
           "analysing them, then count again (1: off)")
      .Add("quiet_min_analyses", &o.quiet_min_analyses,
           "consecutive quiet analyses before quiet_analyse_every carries frames")
      .Add("quiet_max_removed", &o.quiet_max_removed,
           "an analysis removing more keypoints than this is not quiet")
      .Add("carry_reach_px", &o.carry_reach_px,
           "between analyses: the carried suspect map's dilation; keypoints in it are removed (px)")
      .Add("suspect_frames", &o.suspect_frames,
           "a dynamic region stays suspect this many frames (0: off)")
      .Add("suspect_depth_m", &o.suspect_depth_m, "suspect only where the depth still matches (m)")
      .Add("track_history", &o.track_history, "keypoint-track memory (frames)")
      .Add("track_min_moving", &o.track_min_moving, "a track seen moving this often is excluded")
      .Add("remove_lone_seeds", &o.remove_lone_seeds,
           "remove moving seeds and flagged tracks outside every region and the suspect map")
      .Add("lone_seed_persistent_px", &o.lone_seed_persistent_px,
           "> 0: remove a lone seed only when its previous position is this close (px) to a "
           "keypoint flagged in the previous frame")
      .Add("lone_suspect_max_age", &o.lone_suspect_max_age,
           "remove keypoints flagged by the suspect map alone when the cell was in a region at "
           "most this many frames ago (0: never)")
      .Add("refill_min_removed_fraction", &o.refill_min_removed_fraction,
           "refill outside the regions on frames whose regions removed at least this fraction of "
           "the keypoints (0: never)")
      .OnLoaded([this] { options_.Validate(); });
}

std::unique_ptr<KeypointFilter> FastModeFactory::Create(const RunModeContext& context) {
  FastOptions options = options_;
  options.seed = context.seed;
  return std::make_unique<FastFilter>(options, context.sensor.camera, context.orb);
}

namespace {
// FastOptions' defaults except two, measured in fast mode (docs/results.md; the 12 cuts and
// their twins x 3 replicates). The quiet schedule: every third frame of a quiet scene carried
// (session 50: mean ATE 3.540 -> 3.499 mm, recall of the moving keypoints >= 0.909; 7-12 % of
// the frames carried where people walk, a third without them). The residual veto: a standing
// object nearer than the background is not a mover for its larger flow (session 51: recall
// unchanged, 2.7 % fewer removals away from movers, mean ATE 3.527 -> 3.572 mm). Fused mode sets
// the veto in its own defaults (apps/mode_fused.cc) and keeps the quiet schedule off (measured
// worse there, session 52).
FastOptions FastModeDefaults() {
  FastOptions o;
  o.quiet_analyse_every = 2;
  o.residual_static_veto = true;
  return o;
}

const bool kRegistered =
    RegisterRunMode("fast", "geometric moving-object cues: flow, epipolar, depth regions (no DL)",
                    [] { return std::make_unique<FastModeFactory>(FastModeDefaults()); });

}  // namespace
}  // namespace dynorb
