#include "dynorb/dynamic/fast_filter.h"

#include <algorithm>
#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "dynorb/core/timer.h"
#include "dynorb/dynamic/fast_correspondence.h"
#include "dynorb/dynamic/fast_cues.h"
#include "dynorb/dynamic/fast_filter_frame.h"
#include "dynorb/dynamic/motion_ego.h"
#include "dynorb/dynamic/pixel.h"
#include "dynorb/geometry/two_view.h"

namespace dynorb {

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

namespace {

LkOptions LkFromOptions(const FastOptions& options) {
  LkOptions lk;
  lk.window_px = options.lk_window_px;
  lk.levels = options.lk_levels;
  lk.iterations = options.lk_iterations;
  lk.epsilon_px = options.lk_epsilon_px;
  lk.fb_max_px = options.lk_fb_max_px;
  lk.backward_check = !options.lk_fb_candidates_only;
  lk.base_first_px = options.lk_base_first_px;
  lk.base_window_px = options.lk_base_window_px;
  lk.base_shift_min_points = options.lk_base_shift_min_points;
  lk.backward_levels = options.lk_fb_levels;
  return lk;
}

}  // namespace

FastFilter::FastFilter(const FastOptions& options, const PinholeCamera& camera,
                       const OrbOptions& orb)
    : options_((options.Validate(), options)),
      lk_(LkFromOptions(options_)),
      camera_(camera),
      extractor_(orb) {}

bool FastFilter::MaskCoversDetections() const {
  return options_.refill_min_removed_fraction > 0.0 && info_.num_regions > 0 &&
         info_.num_removed >= options_.refill_min_removed_fraction * info_.num_keypoints;
}

int FastFilter::AnalysisInterval() const {
  if (options_.CanCarry() && quiet_analyses_ >= options_.quiet_min_analyses)
    return std::max(options_.analyse_every, options_.quiet_analyse_every);
  return options_.analyse_every;
}

bool FastFilter::LastAnalysisQuiet() const {
  if (!info_.has_previous || info_.num_regions > 0 ||
      info_.num_removed > options_.quiet_max_removed)
    return false;
  return suspect_.empty() || cv::countNonZero(suspect_.Suspect(options_.suspect_frames)) == 0;
}

FilterOutput FastFilter::Filter(const FilterInput& input) {
  if (has_previous_ && frames_since_analysis_ + 1 < AnalysisInterval()) {
    ++frames_since_analysis_;
    return CarryForward(input);
  }
  Stopwatch total, watch;
  timing_ = FastTiming();
  info_ = FastFrameInfo();
  FrameWork w(input, options_);
  // A quiet streak counts consecutive analysed frames: after a carried one it starts again (the
  // first analysis after a carry has no track history nor flagged keypoints to confirm a lone
  // seed, so a mover entering then is confirmed by the next analysis).
  const bool after_carry = frames_since_analysis_ > 0;
  w.after_carry = after_carry;
  frames_since_analysis_ = 0;
  info_.num_keypoints = static_cast<int>(w.n);
  FilterOutput out;
  out.keep.assign(w.n, true);
  cue_bits_.assign(w.n, 0);

  FindCorrespondences(&w);
  timing_.flow_ms = watch.ElapsedMs();
  if (has_previous_) {
    info_.has_previous = true;
    info_.num_tracked = w.corr.num_valid;
    info_.num_retracked = w.corr.num_retracked;
    w.p1 = w.corr.previous;
    for (size_t i = 0; i < w.n; ++i) cue_bits_[i] |= w.corr.valid[i] ? kCueTracked : 0;
    watch.Restart();
    EstimateMotion(&w);
    timing_.ego_ms = watch.ElapsedMs();
    watch.Restart();
    ComputeWarpResidual(&w);  // needed by the F check
    timing_.cues_ms = watch.ElapsedMs();
    watch.Restart();
    EstimateFundamental(&w);
    timing_.fundamental_ms = watch.ElapsedMs();
    watch.Restart();
    Classify(&w);
    timing_.cues_ms += watch.ElapsedMs();
    watch.Restart();
    GrowRegionsAndRemove(&w, &out);
    timing_.region_ms = watch.ElapsedMs();
  }

  last_p1_ = w.p1;
  if (!has_previous_) last_residual_.assign(w.n, -1.f);
  if (input.want_overlay) {
    watch.Restart();
    out.overlay = DrawOverlay(input, w.p1, w.p2, w.final_mask);
    timing_.overlay_ms = watch.ElapsedMs();
  }
  if (!w.final_mask.empty()) out.dynamic_mask = w.final_mask;

  out.judged = has_previous_;
  judged_once_ = judged_once_ || has_previous_;
  // Keep the current frame as the next frame's previous one.
  has_previous_ = true;
  previous_pyramid_ = std::move(w.pyramid);
  previous_descriptors_ = w.descriptors;
  previous_keypoints_ = w.keypoints;
  previous_points_ = w.p2;
  previous_history_ = std::move(w.history);
  previous_depth_ = w.depth.clone();
  KeepPreviousMask(w.final_mask, w.depth.size());
  quiet_analyses_ = LastAnalysisQuiet() ? (after_carry ? 1 : quiet_analyses_ + 1) : 0;
  timing_.total_ms = total.ElapsedMs();
  total_timing_ += timing_;
  ++frames_;
  return out;
}

void FastFilter::KeepPreviousMask(const cv::Mat& mask, cv::Size size) {
  previous_mask_ = mask.empty() ? cv::Mat() : mask.clone();
  if (!options_.ego_previous_removed) return;
  // The flagged keypoints themselves (every removed one, and the lone seeds kept since session
  // 24) are part of the prior too: a region need not cover all of a mover's keypoints.
  for (const cv::Point2f& p : previous_flagged_) {
    if (previous_mask_.empty()) previous_mask_ = cv::Mat::zeros(size, CV_8U);
    cv::circle(previous_mask_, p, 2, cv::Scalar(255), cv::FILLED);
  }
}

FilterOutput FastFilter::CarryForward(const FilterInput& input) {
  Stopwatch total;
  timing_ = FastTiming();
  info_ = FastFrameInfo();
  const std::vector<cv::KeyPoint>& keypoints = input.keypoints->keypoints;
  const size_t n = keypoints.size();
  info_.num_keypoints = static_cast<int>(n);
  FilterOutput out;
  out.keep.assign(n, true);
  out.judged = judged_once_;
  out.analysed = false;
  cue_bits_.assign(n, 0);
  last_p1_.clear();
  last_residual_.assign(n, -1.f);
  const cv::Mat& depth = *input.depth_m;
  const int s = options_.region_scale;
  // The motion since the previous frame: the tracker's prediction, else the last ego-motion.
  std::optional<Rigid3d> prev_from_cur = own_prev_from_cur_;
  if (input.predicted_cam_from_previous_cam)
    prev_from_cur = input.predicted_cam_from_previous_cam->Inverse();
  SuspectMap carried;
  cv::Mat mask;
  if (prev_from_cur && !suspect_.empty()) {
    const cv::Mat low_depth = DownsampleDepth(depth, s, static_cast<float>(options_.max_depth_m));
    carried = PropagateSuspect(suspect_, low_depth, camera_, s, *prev_from_cur,
                               options_.suspect_frames, options_.suspect_depth_m);
    // The carried cells passed the propagation's depth check (the region's depth, warped, against
    // this frame's); dilated like a grown region's mask, which covers the mover's outline corners
    // and part of its own motion since.
    // A keypoint in the suspect map alone is removed up to lone_suspect_max_age (as analysed).
    const int max_age = std::min(options_.suspect_frames, options_.lone_suspect_max_age);
    mask = UpsampleAndDilate(carried.Suspect(max_age), s, depth.size(),
                             static_cast<int>(std::lround(options_.carry_reach_px)));
  }
  std::vector<cv::Point2f> points(n);
  previous_flagged_.clear();
  for (size_t i = 0; i < n; ++i) {
    points[i] = keypoints[i].pt;
    if (mask.empty()) continue;
    if (!mask.at<uint8_t>(NearestPixel(points[i], mask.size()))) continue;
    out.keep[i] = false;
    cue_bits_[i] = kCueSuspect;
    ++info_.num_removed;
    previous_flagged_.push_back(points[i]);
  }
  if (input.want_overlay) out.overlay = DrawOverlay(input, {}, {}, mask);
  if (!mask.empty()) out.dynamic_mask = mask;
  // This frame is the next analysis's previous one: its pyramid, keypoints (no track history:
  // their correspondences were not computed), depth, carried suspect map and removals.
  timing_.region_ms = total.ElapsedMs();
  Stopwatch pyramid;
  previous_pyramid_ = BuildLkPyramid(*input.gray, lk_);
  timing_.flow_ms = pyramid.ElapsedMs();
  previous_keypoints_ = keypoints;
  previous_points_ = std::move(points);
  previous_history_.assign(n, 0);
  previous_depth_ = depth.clone();
  suspect_ = std::move(carried);
  KeepPreviousMask(mask, depth.size());
  timing_.total_ms = total.ElapsedMs();
  total_timing_ += timing_;
  ++frames_;
  return out;
}

// 1. Correspondences of the current keypoints in the previous frame.
void FastFilter::FindCorrespondences(FrameWork* w) {
  const FilterInput& input = w->input;
  // Motion seeds, in priority order: the tracker's motion model, the filter's own chain.
  if (input.predicted_cam_from_previous_cam)
    w->motion_seeds.push_back(input.predicted_cam_from_previous_cam->Inverse());
  if (own_prev_from_cur_) w->motion_seeds.push_back(*own_prev_from_cur_);
  if (options_.method() != CorrespondenceMethod::kOpticalFlow) {
    w->descriptors = extractor_.Describe(*input.keypoints);
    if (has_previous_) {
      w->corr = MatchDescriptors(w->descriptors, previous_descriptors_, previous_points_,
                                 options_.bf_max_distance, options_.bf_best_fraction,
                                 options_.bf_max_ratio);
    }
    return;
  }
  w->pyramid = BuildLkPyramid(*input.gray, lk_);
  if (!has_previous_) return;
  // LK's guess: the first seed, or the filter's own last ego-motion (one frame old; the tracker's
  // prediction is up to the pipeline depth older).
  std::optional<Rigid3d> lk_prev_from_cur;
  if (!w->motion_seeds.empty()) lk_prev_from_cur = w->motion_seeds.front();
  if (options_.lk_seed_own_motion && own_prev_from_cur_) lk_prev_from_cur = own_prev_from_cur_;
  // At most lk_max_points keypoints, spread over the image; LK seeded with the prediction.
  const std::vector<int> subset =
      SpreadSubset(w->keypoints, input.gray->size(), options_.lk_max_points);
  std::vector<cv::Point2f> initial;
  if (options_.lk_predict_initial && lk_prev_from_cur) {
    initial.reserve(subset.size());
    for (int i : subset) {
      const DepthSample z = SampleDepth(w->depth, w->p2[i], w->max_depth);
      cv::Point2f guess =
          WarpToPrevious(camera_, *lk_prev_from_cur, w->p2[i], z.center > 0.f ? z.center : 3.0);
      if (!camera_.InImage(Eigen::Vector2d(guess.x, guess.y))) guess = w->p2[i];
      initial.push_back(guess);
    }
  }
  LkOptions lk = lk_;
  if (!w->after_carry && !options_.lk_base_shift_always) lk.base_shift_min_points = 0;
  w->corr = TrackSubsetWithFlow(previous_pyramid_, w->pyramid, w->p2, subset, initial, lk);
}

// 2. Ego-motion.
void FastFilter::EstimateMotion(FrameWork* w) {
  EgoMotionOptions ego_options;
  ego_options.refine = options_.refine_ego_motion;
  ego_options.seed_rigidity_ratio = options_.ego_rigidity_ratio;
  ego_options.skip_search_gate_px = options_.ego_skip_search_gate_px;
  ego_options.abandon_duplicate_predictions = options_.ego_abandon_duplicates;
  ego_options.max_depth_m = w->max_depth;
  const cv::Mat no_mask;
  // With ego_previous_mask_always the previous regions (and, with ego_previous_removed, the
  // keypoints the previous frame removed) never vote (session 23).
  w->ego = EstimateEgoMotionWithPrior(
      camera_, w->p1, w->p2, w->corr.valid, w->depth, w->motion_seeds,
      options_.ego_skip_previous_mask ? previous_mask_ : no_mask, options_.ego_skip_max_fraction,
      ego_options, options_.ego_previous_mask_always);
  info_.ego_ok = w->ego.ok;
  info_.ego_seed = w->ego.seed_index;
  if (w->ego.ok) {
    own_prev_from_cur_ = w->ego.prev_from_cur;
  } else {
    own_prev_from_cur_.reset();
  }
}

// Rigid-warp residual and depth consistency against the ego-motion.
void FastFilter::ComputeWarpResidual(FrameWork* w) const {
  const size_t n = w->n;
  if (!w->ego.ok) {
    w->warp.residual_px.assign(n, -1.f);
    w->warp.residual.assign(n, CueVote::kUnknown);
    w->warp.depth.assign(n, CueVote::kUnknown);
    return;
  }
  WarpResidualOptions wo;
  wo.residual_px = options_.residual_px;
  wo.residual_rel = options_.residual_rel;
  wo.mismatch_px = options_.residual_mismatch_px;
  // Matched keypoint positions are only as precise as their pyramid level (both frames).
  std::vector<float> level_scale;
  if (!w->corr.previous_index.empty()) {
    level_scale.assign(n, 1.f);
    const double f = extractor_.options().scale_factor;
    for (size_t i = 0; i < n; ++i) {
      const int j = w->corr.previous_index[i];
      if (j < 0) continue;
      const int octave = std::max(w->keypoints[i].octave, previous_keypoints_[j].octave);
      level_scale[i] = static_cast<float>(std::pow(f, std::max(0, octave)));
    }
    wo.tolerance_scale = &level_scale;
  }
  wo.depth_abs_m = options_.depth_abs_m;
  wo.depth_rel = options_.depth_rel;
  wo.max_depth_m = w->max_depth;
  w->warp = WarpResidualCue(camera_, w->ego.prev_from_cur, w->p1, w->p2, w->corr.valid, w->depth,
                            previous_depth_, wo);
}

// 3. Fundamental matrix by RANSAC, checked against the ego-motion.
void FastFilter::EstimateFundamental(FrameWork* w) {
  const size_t n = w->n;
  w->static_ref.assign(n, 0);
  if (!options_.use_epipolar && !options_.use_direction) return;
  std::vector<cv::Point2f> f1, f2;
  std::vector<int> f_index;
  for (size_t i = 0; i < n; ++i) {
    if (!w->corr.for_f[i]) continue;
    f1.push_back(w->p1[i]);
    f2.push_back(w->p2[i]);
    f_index.push_back(static_cast<int>(i));
  }
  if (f1.size() >= 15) {
    // 1 .. 2^31 - 1 (the same as (seed & 0x7fffffff) + 1 below 2^31 - 1, without its overflow).
    cv::setRNGSeed(static_cast<int>(options_.seed % 0x7fffffff) + 1);
    std::vector<uint8_t> inlier_mask;
    const cv::Mat f = cv::findFundamentalMat(f1, f2, cv::FM_RANSAC, options_.f_ransac_px,
                                             options_.f_confidence, inlier_mask);
    if (f.rows == 3 && f.cols == 3) {
      w->have_f = true;
      info_.f_ok = true;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) w->f21(r, c) = f.at<double>(r, c);
      for (size_t k = 0; k < f_index.size(); ++k) w->static_ref[f_index[k]] = inlier_mask[k];
    }
  }
  // Guard against an F that locked onto a dominant mover: most F inliers must agree with the
  // ego-motion (residual cue static).
  if (options_.check_f_with_prediction && w->ego.ok) {
    int agree = 0, judged = 0;
    for (size_t i = 0; i < n; ++i) {
      const CueVote r = w->warp.residual[i];
      if (!w->static_ref[i] || r == CueVote::kUnknown || r == CueVote::kMismatch) continue;
      ++judged;
      agree += r == CueVote::kStatic ? 1 : 0;
    }
    if (!w->have_f || (judged >= 10 && agree < 0.6 * judged)) {
      info_.f_replaced = w->have_f;
      w->f21 = FundamentalFromMotion(camera_, w->ego.prev_from_cur.Inverse());
      w->have_f = true;
      for (size_t i = 0; i < n; ++i) w->static_ref[i] = w->warp.residual[i] == CueVote::kStatic;
    }
  }
}

std::vector<std::pair<std::string, double>> FastFilter::StageTimings() const {
  return {{"flow", timing_.flow_ms},
          {"ego_motion", timing_.ego_ms},
          {"fundamental", timing_.fundamental_ms},
          {"classify", timing_.cues_ms},
          {"region", timing_.region_ms},
          {"overlay", timing_.overlay_ms}};
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