// FastFilter's later stages: the cues' votes and their fusion into seeds (with the backward check
// of the candidates), track memory, suspect map, regions and removal, and the overlay. Filter()
// itself and the earlier stages (correspondences, ego-motion, warp residual, F) are in
// fast_filter.cc.
#include "dynorb/dynamic/fast_filter.h"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "dynorb/dynamic/fast_correspondence.h"
#include "dynorb/dynamic/fast_cues.h"
#include "dynorb/dynamic/fast_filter_frame.h"
#include "dynorb/dynamic/fast_region.h"
#include "dynorb/dynamic/pixel.h"
#include "dynorb/features/orb_matcher.h"

namespace dynorb {
namespace {

bool IsMoving(CueVote v) { return v == CueVote::kMoving; }

}  // namespace

// 4. Cues, the forward-backward check of the candidates, fusion into seeds, track memory.
void FastFilter::Classify(FrameWork* w) {
  const size_t n = w->n;
  const std::vector<cv::Point2f>& p1 = w->p1;
  const std::vector<cv::Point2f>& p2 = w->p2;
  const std::vector<uint8_t>& valid = w->corr.valid;
  WarpResidualResult& warp = w->warp;
  std::vector<CueVote> none(n, CueVote::kUnknown);
  std::vector<CueVote> epi =
      options_.use_epipolar && w->have_f
          ? EpipolarCue(w->f21, p1, p2, valid, options_.epi_t1_px, options_.epi_t2_px)
          : none;
  std::vector<CueVote> dir =
      options_.use_direction && w->have_f
          ? DirectionCue(p1, p2, valid, w->static_ref, options_.direction_max_deg,
                         options_.direction_min_flow_px)
          : none;
  std::vector<CueVote> mag =
      options_.use_magnitude
          ? MagnitudeCue(p1, p2, valid, options_.magnitude_sigmas, options_.magnitude_min_sigma_px,
                         options_.magnitude_abs_diff_px)
          : none;
  const std::vector<CueVote>& res = options_.use_residual ? warp.residual : none;
  const std::vector<CueVote>& dep = options_.use_depth ? warp.depth : none;
  if (options_.method() == CorrespondenceMethod::kOpticalFlow && options_.lk_fb_candidates_only) {
    // Forward–backward check for the points some cue calls moving; a failed track is no evidence.
    std::vector<int> candidates;
    for (size_t i = 0; i < n; ++i) {
      if (valid[i] && (IsMoving(epi[i]) || IsMoving(dir[i]) || IsMoving(mag[i]) ||
                       IsMoving(res[i]) || IsMoving(dep[i]))) {
        candidates.push_back(static_cast<int>(i));
      }
    }
    CheckBackward(previous_pyramid_, w->pyramid, p2, candidates, lk_, &w->corr);
    for (int i : candidates) {
      if (valid[i]) continue;
      epi[i] = dir[i] = mag[i] = warp.residual[i] = warp.depth[i] = CueVote::kUnknown;
      warp.residual_px[i] = -1.f;
      cue_bits_[i] &= static_cast<uint16_t>(~kCueTracked);
    }
    info_.num_tracked = w->corr.num_valid;
  }
  // A residual beyond residual_mismatch_px means a wrong correspondence: no cue votes for it.
  for (size_t i = 0; i < n; ++i) {
    if (warp.residual[i] != CueVote::kMismatch) continue;
    epi[i] = dir[i] = mag[i] = warp.depth[i] = CueVote::kUnknown;
  }
  last_residual_ = warp.residual_px;
  // Track association: the previous keypoint each correspondence lands on (within 2 px).
  std::vector<int> previous_of(n, -1);
  if (!previous_keypoints_.empty()) {
    const KeypointGrid grid(previous_keypoints_, w->input.gray->size(), 8.f);
    std::vector<int> near;
    for (size_t i = 0; i < n; ++i) {
      if (!valid[i]) continue;
      grid.FindInRadius(p1[i].x, p1[i].y, 2.f, &near);
      float best = 5.f;
      for (int j : near) {
        const cv::Point2f d = previous_points_[j] - p1[i];
        if (d.dot(d) < best) best = d.dot(d), previous_of[i] = j;
      }
    }
  }
  w->seed.assign(n, 0);
  w->confident_static.assign(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!valid[i]) continue;
    uint16_t bits = 0;
    double score = 0.0;
    // The frame-pair cues; with residual_static_veto they do not count where the rigid warp with
    // the point's own depth explains its flow (a near object's flow is larger, and an F fitted to
    // a dominant plane can put it off its epipolar line).
    double pair_score = 0.0;
    if (IsMoving(epi[i])) bits |= kCueEpipolar, pair_score += options_.weight_epipolar;
    if (epi[i] == CueVote::kMismatch || res[i] == CueVote::kMismatch) bits |= kCueMismatch;
    if (IsMoving(dir[i])) bits |= kCueDirection, pair_score += options_.weight_direction;
    if (IsMoving(mag[i])) bits |= kCueMagnitude, pair_score += options_.weight_magnitude;
    if (!(options_.residual_static_veto && res[i] == CueVote::kStatic)) score += pair_score;
    if (IsMoving(res[i])) bits |= kCueResidual, score += options_.weight_residual;
    if (IsMoving(dep[i])) bits |= kCueDepth, score += options_.weight_depth;
    if (score >= options_.seed_score) bits |= kCueSeed, w->seed[i] = 1;
    w->confident_static[i] =
        score == 0.0 &&
        (res[i] == CueVote::kStatic || (res[i] == CueVote::kUnknown && epi[i] == CueVote::kStatic));
    cue_bits_[i] |= bits;
  }
  // Track memory: inherit the history of the previous keypoint the correspondence lands on.
  const uint16_t history_mask = static_cast<uint16_t>((1u << options_.track_history) - 1u);
  if (previous_keypoints_.empty()) return;
  for (size_t i = 0; i < n; ++i) {
    const uint16_t h = previous_of[i] >= 0 ? previous_history_[previous_of[i]] : 0;
    w->history[i] = static_cast<uint16_t>(((h << 1) | w->seed[i]) & history_mask);
    if (static_cast<int>(std::bitset<16>(w->history[i]).count()) >= options_.track_min_moving) {
      cue_bits_[i] |= kCueTrack;
    }
  }
}

// 5./6. Temporal suspect map, region growing and the removal itself.
void FastFilter::GrowRegionsAndRemove(FrameWork* w, FilterOutput* out) {
  const size_t n = w->n;
  const cv::Mat& depth = w->depth;
  const std::vector<cv::Point2f>& p1 = w->p1;
  const std::vector<cv::Point2f>& p2 = w->p2;
  const EgoMotionResult& ego = w->ego;
  const cv::Mat low_depth = DownsampleDepth(depth, options_.region_scale, w->max_depth);
  SuspectMap suspect;
  if (ego.ok && options_.suspect_frames > 0) {
    suspect =
        PropagateSuspect(suspect_, low_depth, camera_, options_.region_scale, ego.prev_from_cur,
                         options_.suspect_frames, options_.suspect_depth_m);
  }
  const cv::Mat suspect_low =
      suspect.empty() ? cv::Mat() : suspect.Suspect(options_.suspect_frames);
  RegionResult region;
  if (options_.use_region) {
    std::vector<RegionPoint> seeds, statics;
    for (size_t i = 0; i < n; ++i) {
      if (w->seed[i] || (cue_bits_[i] & kCueTrack)) {
        const float z = SampleDepth(depth, p2[i], w->max_depth).center;
        cv::Point2f motion(0.f, 0.f);
        if (ego.ok && z > 0.f && w->corr.valid[i])
          motion = p1[i] - WarpToPrevious(camera_, ego.prev_from_cur, p2[i], z);
        seeds.push_back({p2[i], z, motion});
      } else if (w->confident_static[i]) {
        statics.push_back({p2[i], 0.f, {}});
      }
    }
    RegionOptions ro;
    ro.scale = options_.region_scale;
    ro.edge_abs_m = options_.region_edge_abs_m;
    ro.edge_rel = options_.region_edge_rel;
    ro.band_m = options_.region_band_m;
    ro.min_seeds = options_.region_min_seeds;
    ro.max_static_ratio = options_.region_max_static_ratio;
    ro.min_coherence = options_.region_min_coherence;
    ro.max_area = options_.region_max_area;
    ro.dilate_px = options_.region_dilate_px;
    ro.max_depth_m = w->max_depth;
    region = GrowRegions(low_depth, depth.size(), seeds, statics, suspect_low, ro);
    info_.num_regions = region.num_accepted;
    w->final_mask = region.mask;
  }
  // How far a keypoint's FAST circle reaches beyond the dilated mask, per octave (0: not at all).
  std::vector<float> octave_reach;
  if (options_.region_octave_reach && region.num_accepted > 0) {
    const double f = extractor_.options().scale_factor;
    for (int o = 0; o < extractor_.options().n_levels; ++o) {
      octave_reach.push_back(
          static_cast<float>(std::max(0.0, 3.0 * std::pow(f, o) - options_.region_dilate_px)));
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const cv::Point px = NearestPixel(p2[i], depth.size());
    const int x = px.x, y = px.y;
    if (!w->final_mask.empty()) {
      const int octave = w->keypoints[i].octave;
      if (w->final_mask.at<uint8_t>(y, x) ||
          (octave > 0 && octave < static_cast<int>(octave_reach.size()) &&
           octave_reach[octave] > 0.f &&
           MaskWithinRadius(w->final_mask, p2[i], octave_reach[octave]))) {
        cue_bits_[i] |= kCueRegion;
      }
    }
    int suspect_age = 255;
    if (!suspect_low.empty()) {
      const int s = options_.region_scale;
      const int lx = std::min(x / s, suspect_low.cols - 1),
                ly = std::min(y / s, suspect_low.rows - 1);
      if (suspect_low.at<uint8_t>(ly, lx)) {
        // Only where the keypoint's own depth still matches the suspect depth.
        const float z = SampleDepth(depth, p2[i], w->max_depth).center;
        if (z > 0.f && std::abs(z - suspect.depth.at<float>(ly, lx)) < options_.suspect_depth_m) {
          cue_bits_[i] |= kCueSuspect;
          suspect_age = suspect.age.at<uint8_t>(ly, lx);
        }
      }
    }
    const uint16_t bits = cue_bits_[i];
    bool lone_seed = !(bits & (kCueRegion | kCueSuspect));
    if (lone_seed && !options_.remove_lone_seeds && (bits & (kCueSeed | kCueTrack)) &&
        options_.lone_seed_persistent_px > 0.0 && w->corr.valid[i]) {
      const double r2 = options_.lone_seed_persistent_px * options_.lone_seed_persistent_px;
      for (const cv::Point2f& q : previous_flagged_) {
        const cv::Point2f d = q - p1[i];
        if (d.x * d.x + d.y * d.y <= r2) {
          lone_seed = false;  // flagged again: removed like a seed with support
          break;
        }
      }
    }
    const bool lone_suspect = !(bits & (kCueSeed | kCueTrack | kCueRegion));
    if ((bits & kCueRegion) ||
        ((bits & (kCueSeed | kCueTrack)) && (options_.remove_lone_seeds || !lone_seed)) ||
        ((bits & kCueSuspect) && (suspect_age <= options_.lone_suspect_max_age || !lone_suspect))) {
      out->keep[i] = false;
      ++info_.num_removed;
      if (bits & (kCueSeed | kCueTrack)) out->moving_points.push_back(p2[i]);
    }
    info_.num_seeds += w->seed[i];
  }
  previous_flagged_.clear();
  for (size_t i = 0; i < n; ++i) {
    if (cue_bits_[i] & (kCueSeed | kCueTrack | kCueRegion | kCueSuspect))
      previous_flagged_.push_back(p2[i]);
  }
  if (ego.ok && options_.use_region) {
    AddToSuspect(region.low_mask, low_depth, &suspect);
    suspect_ = std::move(suspect);
  } else {
    suspect_ = SuspectMap();
  }
}

cv::Mat FastFilter::DrawOverlay(const FilterInput& input, const std::vector<cv::Point2f>& p1,
                                const std::vector<cv::Point2f>& p2, const cv::Mat& mask) const {
  cv::Mat canvas = input.bgr->clone();
  if (!mask.empty()) {
    cv::Mat red(canvas.size(), CV_8UC3, cv::Scalar(0, 0, 255)), blended;
    cv::addWeighted(canvas, 0.65, red, 0.35, 0.0, blended);
    blended.copyTo(canvas, mask);
  }
  for (size_t i = 0; i < p1.size() && i < cue_bits_.size(); ++i) {
    const uint16_t b = cue_bits_[i];
    if (!(b & kCueTracked)) continue;
    cv::Scalar color(0, 200, 0);                                    // static: green
    if (b & kCueMismatch) color = cv::Scalar(0, 220, 220);          // epipolar mismatch: yellow
    if (b & (kCueSeed | kCueTrack)) color = cv::Scalar(0, 0, 255);  // moving seed: red
    cv::line(canvas, p2[i], p1[i], color, 1, cv::LINE_AA);
    if (b & kCueEpipolar)
      cv::circle(canvas, p2[i], 5, cv::Scalar(255, 0, 255), 1, cv::LINE_AA);  // magenta
  }
  cv::putText(
      canvas,
      "fast: flow static (green) / moving (red) / mismatch (yellow), epipolar outlier (magenta)",
      cv::Point(6, 14), cv::FONT_HERSHEY_SIMPLEX, 0.38, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  char text[160];
  std::snprintf(text, sizeof(text), "tracked %d seeds %d removed %d regions %d ego-seed %d%s%s",
                info_.num_tracked, info_.num_seeds, info_.num_removed, info_.num_regions,
                info_.ego_seed, info_.f_replaced ? " F-replaced" : "",
                info_.ego_ok ? "" : " no-ego");
  cv::putText(canvas, text, cv::Point(6, 30), cv::FONT_HERSHEY_SIMPLEX, 0.38,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return canvas;
}

}  // namespace dynorb
