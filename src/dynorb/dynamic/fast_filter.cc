#include "dynorb/dynamic/fast_filter.h"

#include <algorithm>
#include <bitset>
#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "dynorb/core/timer.h"
#include "dynorb/dynamic/fast_correspondence.h"
#include "dynorb/dynamic/fast_cues.h"
#include "dynorb/dynamic/motion_ego.h"
#include "dynorb/features/orb_matcher.h"
#include "dynorb/geometry/two_view.h"

namespace dynorb {
namespace {

bool IsMoving(CueVote v) { return v == CueVote::kMoving; }

}  // namespace

FastTiming& FastTiming::operator+=(const FastTiming& o) {
  flow_ms += o.flow_ms;
  ego_ms += o.ego_ms;
  fundamental_ms += o.fundamental_ms;
  cues_ms += o.cues_ms;
  region_ms += o.region_ms;
  overlay_ms += o.overlay_ms;
  total_ms += o.total_ms;
  return *this;
}

FastFilter::FastFilter(const FastOptions& options, const PinholeCamera& camera, const OrbOptions& orb)
    : options_((options.Validate(), options)), camera_(camera), extractor_(orb) {}

FilterOutput FastFilter::Filter(const FilterInput& input) {
  Stopwatch total, watch;
  timing_ = FastTiming();
  info_ = FastFrameInfo();
  const std::vector<cv::KeyPoint>& keypoints = input.keypoints->keypoints;
  const size_t n = keypoints.size();
  const cv::Mat& depth = *input.depth_m;
  FilterOutput out;
  out.keep.assign(n, true);
  cue_bits_.assign(n, 0);
  std::vector<cv::Point2f> p2(n);
  for (size_t i = 0; i < n; ++i) p2[i] = keypoints[i].pt;
  const float max_depth = static_cast<float>(options_.max_depth_m);

  // 1. Correspondences.
  LkOptions lk;
  lk.window_px = options_.lk_window_px;
  lk.levels = options_.lk_levels;
  lk.iterations = options_.lk_iterations;
  lk.fb_max_px = options_.lk_fb_max_px;
  lk.backward_check = !options_.lk_fb_candidates_only;
  lk.base_first_px = options_.lk_base_first_px;
  lk.backward_levels = options_.lk_fb_levels;
  std::vector<cv::Mat> pyramid;
  cv::Mat descriptors;
  Correspondences corr;
  // Motion seeds, in priority order: the tracker's motion model, the filter's own chain.
  std::vector<Rigid3d> motion_seeds;
  if (input.predicted_cam_from_previous_cam) motion_seeds.push_back(input.predicted_cam_from_previous_cam->Inverse());
  if (own_prev_from_cur_) motion_seeds.push_back(*own_prev_from_cur_);
  // LK's guess: the first seed, or the filter's own last ego-motion (one frame old; the tracker's
  // prediction is up to the pipeline depth older).
  std::optional<Rigid3d> lk_prev_from_cur;
  if (!motion_seeds.empty()) lk_prev_from_cur = motion_seeds.front();
  if (options_.lk_seed_own_motion && own_prev_from_cur_) lk_prev_from_cur = own_prev_from_cur_;
  if (options_.method() == CorrespondenceMethod::kOpticalFlow) {
    pyramid = BuildLkPyramid(*input.gray, lk);
    if (has_previous_) {
      // At most lk_max_points keypoints, spread over the image; LK seeded with the prediction.
      const std::vector<int> subset = SpreadSubset(keypoints, input.gray->size(), options_.lk_max_points);
      std::vector<cv::Point2f> initial;
      if (options_.lk_predict_initial && lk_prev_from_cur) {
        initial.reserve(subset.size());
        for (int i : subset) {
          const DepthSample z = SampleDepth(depth, p2[i], max_depth);
          cv::Point2f guess = WarpToPrevious(camera_, *lk_prev_from_cur, p2[i], z.center > 0.f ? z.center : 3.0);
          if (!camera_.InImage(Eigen::Vector2d(guess.x, guess.y))) guess = p2[i];
          initial.push_back(guess);
        }
      }
      corr = TrackSubsetWithFlow(previous_pyramid_, pyramid, p2, subset, initial, lk);
    }
  } else {
    descriptors = extractor_.Describe(*input.keypoints);
    if (has_previous_) {
      corr = MatchDescriptors(descriptors, previous_descriptors_, previous_points_, options_.bf_max_distance,
                              options_.bf_best_fraction, options_.bf_max_ratio);
    }
  }
  timing_.flow_ms = watch.ElapsedMs();

  std::vector<uint16_t> history(n, 0);
  cv::Mat final_mask;
  std::vector<cv::Point2f> p1;
  if (has_previous_) {
    info_.has_previous = true;
    info_.num_tracked = corr.num_valid;
    p1 = corr.previous;
    const std::vector<uint8_t>& valid = corr.valid;
    for (size_t i = 0; i < n; ++i) cue_bits_[i] |= valid[i] ? kCueTracked : 0;

    // 2. Ego-motion.
    watch.Restart();
    EgoMotionOptions ego_options;
    ego_options.refine = options_.refine_ego_motion;
    ego_options.seed_rigidity_ratio = options_.ego_rigidity_ratio;
    ego_options.max_depth_m = max_depth;
    const EgoMotionResult ego =
        EstimateEgoMotion(camera_, p1, p2, valid, depth, motion_seeds, ego_options);
    info_.ego_ok = ego.ok;
    info_.ego_seed = ego.seed_index;
    if (ego.ok) {
      own_prev_from_cur_ = ego.prev_from_cur;
    } else {
      own_prev_from_cur_.reset();
    }
    timing_.ego_ms = watch.ElapsedMs();

    // Rigid-warp residual (needed by the F check).
    watch.Restart();
    WarpResidualResult warp;
    if (ego.ok) {
      WarpResidualOptions wo;
      wo.residual_px = options_.residual_px;
      wo.residual_rel = options_.residual_rel;
      wo.mismatch_px = options_.residual_mismatch_px;
      // Matched keypoint positions are only as precise as their pyramid level (both frames).
      std::vector<float> level_scale;
      if (!corr.previous_index.empty()) {
        level_scale.assign(n, 1.f);
        const double f = extractor_.options().scale_factor;
        for (size_t i = 0; i < n; ++i) {
          const int j = corr.previous_index[i];
          if (j < 0) continue;
          const int octave = std::max(keypoints[i].octave, previous_keypoints_[j].octave);
          level_scale[i] = static_cast<float>(std::pow(f, std::max(0, octave)));
        }
        wo.tolerance_scale = &level_scale;
      }
      wo.depth_abs_m = options_.depth_abs_m;
      wo.depth_rel = options_.depth_rel;
      wo.max_depth_m = max_depth;
      warp = WarpResidualCue(camera_, ego.prev_from_cur, p1, p2, valid, depth, previous_depth_, wo);
    } else {
      warp.residual_px.assign(n, -1.f);
      warp.residual.assign(n, CueVote::kUnknown);
      warp.depth.assign(n, CueVote::kUnknown);
    }
    timing_.cues_ms = watch.ElapsedMs();

    // 3. Fundamental matrix by RANSAC.
    watch.Restart();
    Eigen::Matrix3d f21 = Eigen::Matrix3d::Zero();
    std::vector<uint8_t> static_ref(n, 0);
    bool have_f = false;
    if (options_.use_epipolar || options_.use_direction) {
      std::vector<cv::Point2f> f1, f2;
      std::vector<int> f_index;
      for (size_t i = 0; i < n; ++i) {
        if (!corr.for_f[i]) continue;
        f1.push_back(p1[i]);
        f2.push_back(p2[i]);
        f_index.push_back(static_cast<int>(i));
      }
      if (f1.size() >= 15) {
        cv::setRNGSeed(static_cast<int>(options_.seed & 0x7fffffff) + 1);
        std::vector<uint8_t> inlier_mask;
        const cv::Mat f = cv::findFundamentalMat(f1, f2, cv::FM_RANSAC, options_.f_ransac_px, options_.f_confidence,
                                                 inlier_mask);
        if (f.rows == 3 && f.cols == 3) {
          have_f = true;
          info_.f_ok = true;
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) f21(r, c) = f.at<double>(r, c);
          for (size_t k = 0; k < f_index.size(); ++k) static_ref[f_index[k]] = inlier_mask[k];
        }
      }
      // Guard against an F that locked onto a dominant mover: most F inliers must agree with the
      // ego-motion (residual cue static).
      if (options_.check_f_with_prediction && ego.ok) {
        int agree = 0, judged = 0;
        for (size_t i = 0; i < n; ++i) {
          const CueVote r = warp.residual[i];
          if (!static_ref[i] || r == CueVote::kUnknown || r == CueVote::kMismatch) continue;
          ++judged;
          agree += r == CueVote::kStatic ? 1 : 0;
        }
        if (!have_f || (judged >= 10 && agree < 0.6 * judged)) {
          info_.f_replaced = have_f;
          f21 = FundamentalFromMotion(camera_, ego.prev_from_cur.Inverse());
          have_f = true;
          for (size_t i = 0; i < n; ++i) static_ref[i] = warp.residual[i] == CueVote::kStatic;
        }
      }
    }
    timing_.fundamental_ms = watch.ElapsedMs();

    // 4. Cues and fusion.
    watch.Restart();
    std::vector<CueVote> none(n, CueVote::kUnknown);
    std::vector<CueVote> epi = options_.use_epipolar && have_f
                                         ? EpipolarCue(f21, p1, p2, valid, options_.epi_t1_px, options_.epi_t2_px)
                                         : none;
    std::vector<CueVote> dir =
        options_.use_direction && have_f
            ? DirectionCue(p1, p2, valid, static_ref, options_.direction_max_deg, options_.direction_min_flow_px)
            : none;
    std::vector<CueVote> mag =
        options_.use_magnitude ? MagnitudeCue(p1, p2, valid, options_.magnitude_sigmas, options_.magnitude_min_sigma_px,
                                              options_.magnitude_abs_diff_px)
                               : none;
    const std::vector<CueVote>& res = options_.use_residual ? warp.residual : none;
    const std::vector<CueVote>& dep = options_.use_depth ? warp.depth : none;
    if (options_.method() == CorrespondenceMethod::kOpticalFlow && options_.lk_fb_candidates_only) {
      // Forward–backward check for the points some cue calls moving; a failed track is no evidence.
      std::vector<int> candidates;
      for (size_t i = 0; i < n; ++i) {
        if (valid[i] && (IsMoving(epi[i]) || IsMoving(dir[i]) || IsMoving(mag[i]) || IsMoving(res[i]) ||
                         IsMoving(dep[i]))) {
          candidates.push_back(static_cast<int>(i));
        }
      }
      CheckBackward(previous_pyramid_, pyramid, p2, candidates, lk, &corr);
      for (int i : candidates) {
        if (valid[i]) continue;
        epi[i] = dir[i] = mag[i] = warp.residual[i] = warp.depth[i] = CueVote::kUnknown;
        warp.residual_px[i] = -1.f;
        cue_bits_[i] &= static_cast<uint16_t>(~kCueTracked);
      }
      info_.num_tracked = corr.num_valid;
    }
    // A residual beyond residual_mismatch_px means a wrong correspondence: no cue votes for it.
    for (size_t i = 0; i < n; ++i) {
      if (warp.residual[i] != CueVote::kMismatch) continue;
      epi[i] = dir[i] = mag[i] = warp.depth[i] = CueVote::kUnknown;
    }
    last_residual_ = warp.residual_px;
    std::vector<uint8_t> seed(n, 0), confident_static(n, 0);
    for (size_t i = 0; i < n; ++i) {
      if (!valid[i]) continue;
      uint16_t bits = 0;
      double score = 0.0;
      if (IsMoving(epi[i])) bits |= kCueEpipolar, score += options_.weight_epipolar;
      if (epi[i] == CueVote::kMismatch || res[i] == CueVote::kMismatch) bits |= kCueMismatch;
      if (IsMoving(dir[i])) bits |= kCueDirection, score += options_.weight_direction;
      if (IsMoving(mag[i])) bits |= kCueMagnitude, score += options_.weight_magnitude;
      if (IsMoving(res[i])) bits |= kCueResidual, score += options_.weight_residual;
      if (IsMoving(dep[i])) bits |= kCueDepth, score += options_.weight_depth;
      if (score >= options_.seed_score) bits |= kCueSeed, seed[i] = 1;
      confident_static[i] = score == 0.0 && (res[i] == CueVote::kStatic || (res[i] == CueVote::kUnknown &&
                                                                             epi[i] == CueVote::kStatic));
      cue_bits_[i] |= bits;
    }
    // Track memory: inherit the history of the previous keypoint the correspondence lands on.
    const uint16_t history_mask = static_cast<uint16_t>((1u << options_.track_history) - 1u);
    if (!previous_keypoints_.empty()) {
      const KeypointGrid grid(previous_keypoints_, input.gray->size(), 8.f);
      std::vector<int> near;
      for (size_t i = 0; i < n; ++i) {
        uint16_t h = 0;
        if (valid[i]) {
          grid.FindInRadius(p1[i].x, p1[i].y, 2.f, &near);
          float best = 5.f;
          for (int j : near) {
            const cv::Point2f d = previous_points_[j] - p1[i];
            if (d.dot(d) < best) best = d.dot(d), h = previous_history_[j];
          }
        }
        history[i] = static_cast<uint16_t>(((h << 1) | seed[i]) & history_mask);
        if (static_cast<int>(std::bitset<16>(history[i]).count()) >= options_.track_min_moving) {
          cue_bits_[i] |= kCueTrack;
        }
      }
    }
    timing_.cues_ms += watch.ElapsedMs();

    // 5./6. Temporal suspect map and region growing.
    watch.Restart();
    const cv::Mat low_depth = DownsampleDepth(depth, options_.region_scale, max_depth);
    SuspectMap suspect;
    if (ego.ok && options_.suspect_frames > 0) {
      suspect = PropagateSuspect(suspect_, low_depth, camera_, options_.region_scale, ego.prev_from_cur,
                                 options_.suspect_frames, options_.suspect_depth_m);
    }
    const cv::Mat suspect_low = suspect.empty() ? cv::Mat() : suspect.Suspect(options_.suspect_frames);
    RegionResult region;
    if (options_.use_region) {
      std::vector<RegionPoint> seeds, statics;
      for (size_t i = 0; i < n; ++i) {
        if (seed[i] || (cue_bits_[i] & kCueTrack)) {
          const float z = SampleDepth(depth, p2[i], max_depth).center;
          cv::Point2f motion(0.f, 0.f);
          if (ego.ok && z > 0.f && valid[i]) motion = p1[i] - WarpToPrevious(camera_, ego.prev_from_cur, p2[i], z);
          seeds.push_back({p2[i], z, motion});
        } else if (confident_static[i]) {
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
      ro.max_depth_m = max_depth;
      region = GrowRegions(low_depth, depth.size(), seeds, statics, suspect_low, ro);
      info_.num_regions = region.num_accepted;
      final_mask = region.mask;
    }
    for (size_t i = 0; i < n; ++i) {
      const int x = std::clamp(static_cast<int>(std::lround(p2[i].x)), 0, depth.cols - 1);
      const int y = std::clamp(static_cast<int>(std::lround(p2[i].y)), 0, depth.rows - 1);
      if (!final_mask.empty() && final_mask.at<uint8_t>(y, x)) cue_bits_[i] |= kCueRegion;
      if (!suspect_low.empty()) {
        const int s = options_.region_scale;
        const int lx = std::min(x / s, suspect_low.cols - 1), ly = std::min(y / s, suspect_low.rows - 1);
        if (suspect_low.at<uint8_t>(ly, lx)) {
          // Only where the keypoint's own depth still matches the suspect depth.
          const float z = SampleDepth(depth, p2[i], max_depth).center;
          if (z > 0.f && std::abs(z - suspect.depth.at<float>(ly, lx)) < options_.suspect_depth_m) {
            cue_bits_[i] |= kCueSuspect;
          }
        }
      }
      if (cue_bits_[i] & (kCueSeed | kCueTrack | kCueRegion | kCueSuspect)) {
        out.keep[i] = false;
        ++info_.num_removed;
      }
      info_.num_seeds += seed[i];
    }
    if (ego.ok && options_.use_region) {
      AddToSuspect(region.low_mask, low_depth, &suspect);
      suspect_ = std::move(suspect);
    } else {
      suspect_ = SuspectMap();
    }
    timing_.region_ms = watch.ElapsedMs();
  }

  last_p1_ = p1;
  if (!has_previous_) last_residual_.assign(n, -1.f);
  if (input.want_overlay) {
    watch.Restart();
    out.overlay = DrawOverlay(input, p1, p2, final_mask);
    timing_.overlay_ms = watch.ElapsedMs();
  }
  if (!final_mask.empty()) out.dynamic_mask = final_mask;

  out.judged = has_previous_;
  // Keep the current frame as the next frame's previous one.
  has_previous_ = true;
  previous_pyramid_ = std::move(pyramid);
  previous_descriptors_ = descriptors;
  previous_keypoints_ = keypoints;
  previous_points_ = p2;
  previous_history_ = std::move(history);
  previous_depth_ = depth.clone();
  timing_.total_ms = total.ElapsedMs();
  total_timing_ += timing_;
  ++frames_;
  return out;
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
    cv::Scalar color(0, 200, 0);                                 // static: green
    if (b & kCueMismatch) color = cv::Scalar(0, 220, 220);       // epipolar mismatch: yellow
    if (b & (kCueSeed | kCueTrack)) color = cv::Scalar(0, 0, 255);  // moving seed: red
    cv::line(canvas, p2[i], p1[i], color, 1, cv::LINE_AA);
    if (b & kCueEpipolar) cv::circle(canvas, p2[i], 5, cv::Scalar(255, 0, 255), 1, cv::LINE_AA);  // magenta
  }
  cv::putText(canvas, "fast: flow static (green) / moving (red) / mismatch (yellow), epipolar outlier (magenta)",
              cv::Point(6, 14), cv::FONT_HERSHEY_SIMPLEX, 0.38, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  char text[160];
  std::snprintf(text, sizeof(text), "tracked %d seeds %d removed %d regions %d ego-seed %d%s%s", info_.num_tracked,
                info_.num_seeds, info_.num_removed, info_.num_regions, info_.ego_seed, info_.f_replaced ? " F-replaced" : "",
                info_.ego_ok ? "" : " no-ego");
  cv::putText(canvas, text, cv::Point(6, 30), cv::FONT_HERSHEY_SIMPLEX, 0.38, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  return canvas;
}

std::vector<std::pair<std::string, double>> FastFilter::StageTimings() const {
  return {{"flow", timing_.flow_ms},       {"ego_motion", timing_.ego_ms}, {"fundamental", timing_.fundamental_ms},
          {"classify", timing_.cues_ms},   {"region", timing_.region_ms},  {"overlay", timing_.overlay_ms}};
}

std::vector<std::pair<std::string, std::vector<bool>>> FastFilter::CueFlags() const {
  static const std::pair<const char*, FastCue> kCues[] = {
      {"epipolar", kCueEpipolar}, {"direction", kCueDirection}, {"magnitude", kCueMagnitude},
      {"residual", kCueResidual}, {"depth", kCueDepth},         {"seed", kCueSeed},
      {"track", kCueTrack},       {"suspect", kCueSuspect},     {"region", kCueRegion},
      {"mismatch", kCueMismatch}};
  std::vector<std::pair<std::string, std::vector<bool>>> cues;
  for (const auto& [name, bit] : kCues) {
    std::vector<bool> flags(cue_bits_.size());
    for (size_t i = 0; i < cue_bits_.size(); ++i) flags[i] = (cue_bits_[i] & bit) != 0;
    cues.emplace_back(name, std::move(flags));
  }
  return cues;
}

}  // namespace dynorb
