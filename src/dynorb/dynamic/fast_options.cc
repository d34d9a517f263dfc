#include "dynorb/dynamic/fast_options.h"

#include "dynorb/core/error.h"

namespace dynorb {
namespace {
void Require(bool ok, const std::string& what) {
  if (!ok) throw InputError("fast." + what);
}
}  // namespace

void FastOptions::Validate() const {
  Require(correspondences == "flow" || correspondences == "descriptors",
          "correspondences must be 'flow' or 'descriptors', got '" + correspondences + "'");
  Require(lk_window_px >= 5 && lk_window_px <= 101 && lk_window_px % 2 == 1,
          "lk_window_px must be odd and 5..101");
  Require(lk_levels >= 0 && lk_levels <= 6, "lk_levels must be in [0, 6]");
  Require(lk_iterations >= 1, "lk_iterations must be >= 1");
  Require(lk_fb_max_px > 0.0, "lk_fb_max_px must be > 0");
  Require(bf_best_fraction > 0.0 && bf_best_fraction <= 1.0, "bf_best_fraction must be in (0, 1]");
  Require(bf_max_distance >= 0 && bf_max_distance <= 256, "bf_max_distance must be in [0, 256]");
  Require(lk_max_points >= 0, "lk_max_points must be >= 0 (0: all)");
  Require(lk_base_first_px >= 0.0, "lk_base_first_px must be >= 0 (0: off)");
  Require(lk_base_shift_min_points >= 0, "lk_base_shift_min_points must be >= 0 (0: off)");
  Require(lk_base_window_px == 0 || (lk_base_window_px >= 5 && lk_base_window_px % 2 == 1 &&
                                     lk_base_window_px <= lk_window_px),
          "lk_base_window_px must be 0 (lk_window_px) or odd, >= 5 and <= lk_window_px");
  Require(lk_fb_levels >= 0, "lk_fb_levels must be >= 0");
  Require(ego_skip_max_fraction >= 0.0 && ego_skip_max_fraction <= 1.0,
          "ego_skip_max_fraction must be in [0, 1]");
  Require(ego_skip_search_gate_px >= 0.0, "ego_skip_search_gate_px must be >= 0");
  Require(ego_rigidity_ratio == 0.0 || ego_rigidity_ratio >= 1.0, "ego_rigidity_ratio must be 0 (off) or >= 1");
  Require(bf_max_ratio > 0.0 && bf_max_ratio <= 1.0, "bf_max_ratio must be in (0, 1]");
  Require(residual_mismatch_px > 0.0, "residual_mismatch_px must be > 0");
  Require(f_ransac_px > 0.0, "f_ransac_px must be > 0");
  Require(f_confidence > 0.0 && f_confidence < 1.0, "f_confidence must be in (0, 1)");
  Require(epi_t1_px > 0.0 && epi_t2_px > epi_t1_px, "epipolar thresholds need 0 < epi_t1_px < epi_t2_px");
  Require(direction_max_deg > 0.0 && direction_max_deg <= 180.0, "direction_max_deg must be in (0, 180]");
  Require(direction_min_flow_px >= 0.0, "direction_min_flow_px must be >= 0");
  Require(magnitude_sigmas > 0.0 && magnitude_min_sigma_px >= 0.0 && magnitude_abs_diff_px > 0.0,
          "magnitude_* must be positive");
  Require(residual_px > 0.0 && residual_rel >= 0.0, "residual_px must be > 0 and residual_rel >= 0");
  Require(depth_abs_m > 0.0 && depth_rel >= 0.0, "depth_abs_m must be > 0 and depth_rel >= 0");
  Require(max_depth_m > 0.0, "max_depth_m must be > 0");
  Require(weight_residual >= 0.0 && weight_depth >= 0.0 && weight_epipolar >= 0.0 && weight_direction >= 0.0 &&
              weight_magnitude >= 0.0,
          "weights must be >= 0");
  Require(seed_score > 0.0, "seed_score must be > 0");
  Require(region_scale >= 1 && region_scale <= 16, "region_scale must be in [1, 16]");
  Require(region_edge_abs_m >= 0.0 && region_edge_rel >= 0.0 && region_band_m > 0.0, "region depth steps must be >= 0");
  Require(region_min_seeds >= 1, "region_min_seeds must be >= 1");
  Require(region_max_static_ratio >= 0.0 && region_max_static_ratio <= 1.0, "region_max_static_ratio must be in [0, 1]");
  Require(region_max_area > 0.0 && region_max_area <= 1.0, "region_max_area must be in (0, 1]");
  Require(region_dilate_px >= 0 && region_dilate_px <= 50, "region_dilate_px must be in [0, 50]");
  Require(suspect_frames >= 0 && suspect_frames <= 30, "suspect_frames must be in [0, 30]");
  Require(analyse_every >= 1 && analyse_every <= 8, "analyse_every must be in [1, 8]");
  Require(analyse_every == 1 || method() == CorrespondenceMethod::kOpticalFlow,
          "analyse_every > 1 needs correspondences: flow");
  Require(analyse_every == 1 || (use_region && suspect_frames > 0),
          "analyse_every > 1 needs use_region and suspect_frames > 0 (the frames between analyses "
          "carry the suspect map)");
  Require(quiet_analyse_every >= 1 && quiet_analyse_every <= 8,
          "quiet_analyse_every must be in [1, 8]");
  Require(quiet_min_analyses >= 1, "quiet_min_analyses must be >= 1");
  Require(quiet_max_removed >= 0, "quiet_max_removed must be >= 0");
  Require(carry_reach_px >= 0.0 && carry_reach_px <= 64.0, "carry_reach_px must be in [0, 64]");
  Require(suspect_depth_m > 0.0, "suspect_depth_m must be > 0");
  Require(track_history >= 1 && track_history <= 16, "track_history must be in [1, 16]");
  Require(refill_min_removed_fraction >= 0.0 && refill_min_removed_fraction <= 1.0,
          "refill_min_removed_fraction must be in [0, 1] (0: never refill)");
  Require(track_min_moving >= 1, "track_min_moving must be >= 1 (larger than track_history disables it)");
  Require(lk_epsilon_px > 0.0 && lk_epsilon_px <= 1.0, "lk_epsilon_px must be in (0, 1]");
  Require(lone_seed_persistent_px >= 0.0 && lone_seed_persistent_px <= 50.0,
          "lone_seed_persistent_px must be in [0, 50] (0: every lone seed is removed)");
  Require(lone_suspect_max_age >= 0 && lone_suspect_max_age <= 30,
          "lone_suspect_max_age must be in [0, 30] (0: keypoints flagged by the suspect map alone "
          "are kept)");
}

}  // namespace dynorb
