// End-to-end: the FAST filter on a short synthetic walking sequence (rendered in memory by the
// synthetic generator) against its ground-truth masks, both correspondence methods, and
// determinism of a second run.
#include "dynorb/dynamic/fast_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include <opencv2/imgproc.hpp>

#include "dynorb/core/error.h"
#include "dynorb/dynamic/fast_clip_test_util.h"
#include "dynorb/dynamic/fast_region.h"

namespace dynorb {
namespace {

class FastFilterSequence : public ::testing::Test {
 protected:
  // 24 consecutive frames of a 150-frame walking_xyz with people in view.
  static void SetUpTestSuite() { clip_ = new Clip(RenderClip("walking_xyz", 7, 150, 100, 24)); }
  static void TearDownTestSuite() { delete clip_; }

  // Counts over keypoints on objects moving in that frame; keypoints on objects standing still
  // are not counted (as stats.json's dynamic_keypoints.moving_now).
  struct Result {
    long long tp = 0, fp = 0, fn = 0;
    std::vector<std::vector<bool>> keep;
    std::vector<std::vector<uint16_t>> bits;  // FastFilter::cue_bits() per frame
    std::vector<std::vector<cv::KeyPoint>> keypoints;
    std::vector<cv::Mat> masks;  // FilterOutput::dynamic_mask per frame
    std::vector<FastFrameInfo> info;
    std::vector<bool> covers;  // MaskCoversDetections() after each frame
    std::vector<bool> judged;  // FilterOutput::judged
    std::vector<std::vector<cv::Point2f>> previous;  // FastFilter::previous_positions()
    std::vector<std::vector<uint8_t>> tracked;       // kCueTracked per keypoint
    double precision() const { return tp + fp > 0 ? static_cast<double>(tp) / (tp + fp) : 0.0; }
    double recall() const { return tp + fn > 0 ? static_cast<double>(tp) / (tp + fn) : 0.0; }
  };

  static Result Run(const FastOptions& options) {
    FastFilter filter(options, clip_->camera);
    const OrbExtractor extractor;
    Result result;
    const std::vector<ClipFrame>& frames = clip_->frames;
    for (size_t i = 0; i < frames.size(); ++i) {
      const ClipFrame& f = frames[i];
      const KeypointSet set = extractor.Detect(f.gray);
      FilterInput input = ClipInput(f, set, i);
      if (i >= 2) {  // Constant-velocity prediction from the two previous ground-truth poses.
        const Rigid3d& a = frames[i - 2].world_from_cam;
        const Rigid3d& b = frames[i - 1].world_from_cam;
        input.predicted_cam_from_previous_cam = b.Inverse() * a;
      }
      const FilterOutput out = filter.Filter(input);
      EXPECT_EQ(out.keep.size(), static_cast<size_t>(set.size()));
      result.keep.push_back(out.keep);
      result.bits.push_back(filter.cue_bits());
      result.keypoints.push_back(set.keypoints);
      result.masks.push_back(out.dynamic_mask);
      result.info.push_back(filter.info());
      result.covers.push_back(filter.MaskCoversDetections());
      result.judged.push_back(out.judged);
      result.previous.push_back(filter.previous_positions());
      std::vector<uint8_t> tracked(set.size(), 0);
      for (int k = 0; k < set.size(); ++k) tracked[k] = (filter.cue_bits()[k] & kCueTracked) != 0;
      result.tracked.push_back(tracked);
      if (i == 0) continue;
      if (std::getenv("FAST_DEBUG")) {
        int tt = 0, tr = 0, ts = 0, st = 0, sr = 0, ss = 0;
        std::vector<float> rm, rs;
        for (int k = 0; k < set.size(); ++k) {
          const cv::Point p = KeypointPixel(set.keypoints[k], f.mask.size());
          const bool truth = f.mask.at<uint8_t>(p) != 0;
          const uint16_t b = filter.cue_bits()[k];
          if (!(b & kCueTracked)) continue;
          (truth ? tt : st)++;
          if (b & kCueResidual) (truth ? tr : sr)++;
          if (filter.residuals_px()[k] >= 0) (truth ? rm : rs).push_back(filter.residuals_px()[k]);
          if (b & kCueSeed) (truth ? ts : ss)++;
        }
        std::printf("frame %zu ego %d seed %d cov? tracked mover %d res %d seed %d | static %d res %d seed %d\n", i,
                    filter.info().ego_ok, filter.info().ego_seed, tt, tr, ts, st, sr, ss);
        for (auto* v : {&rm, &rs}) {
          std::sort(v->begin(), v->end());
          if (v->empty()) continue;
          std::printf("   %s p10 %.2f p50 %.2f p90 %.2f p99 %.2f\n", v == &rm ? "mover" : "static", (*v)[v->size() / 10],
                      (*v)[v->size() / 2], (*v)[v->size() * 9 / 10], (*v)[v->size() * 99 / 100]);
        }
      }
      for (int k = 0; k < set.size(); ++k) {
        const cv::Point p = KeypointPixel(set.keypoints[k], f.mask.size());
        if (f.still.at<uint8_t>(p) != 0) continue;
        const bool truth = f.mask.at<uint8_t>(p) != 0, removed = !out.keep[k];
        result.tp += truth && removed;
        result.fp += !truth && removed;
        result.fn += truth && !removed;
      }
    }
    if (std::getenv("FAST_DEBUG")) {
      const FastTiming& t = filter.total_timing();
      const double n = std::max(1, filter.frames());
      std::printf("ms/frame: total %.2f flow %.2f ego %.2f F %.2f cues %.2f region %.2f\n", t.total_ms / n,
                  t.flow_ms / n, t.ego_ms / n, t.fundamental_ms / n, t.cues_ms / n, t.region_ms / n);
    }
    return result;
  }

  static Clip* clip_;
};
Clip* FastFilterSequence::clip_ = nullptr;

TEST_F(FastFilterSequence, FlowMeetsPrecisionRecallAndIsDeterministic) {
  const Result a = Run(FastOptions());
  std::printf("flow: tp %lld fp %lld fn %lld precision %.3f recall %.3f\n", a.tp, a.fp, a.fn, a.precision(),
              a.recall());
  ASSERT_GT(a.tp + a.fn, 100) << "the test frames should show people";
  // Regression floors of the current implementation (measured 0.64 / 0.70 on this 24-frame clip,
  // session 24; 0.52 / 0.70 before lone seeds were kept). Counted on the objects moving in each
  // frame; the targets are recall >= 0.9, precision >= 0.8: see docs/fast_mode.md for the
  // 300-frame and full-length numbers.
  EXPECT_GE(a.precision(), 0.5);
  EXPECT_GE(a.recall(), 0.6);
  const Result b = Run(FastOptions());
  EXPECT_EQ(a.keep, b.keep);
}

TEST_F(FastFilterSequence, OctaveReachAlsoRemovesCoarseCornersTouchingARegion) {
  FastOptions options;
  const Result off = Run(options);
  options.region_octave_reach = true;
  const Result on = Run(options);
  ASSERT_EQ(off.keep.size(), on.keep.size());
  const double f = OrbOptions().scale_factor;
  int extra = 0;
  for (size_t i = 0; i < on.keep.size(); ++i) {
    ASSERT_EQ(off.keypoints[i].size(), on.keypoints[i].size());
    for (size_t k = 0; k < on.keep[i].size(); ++k) {
      // Only removals are added, and each added one is a coarse corner whose reach touches the
      // (unchanged) region mask without its centre lying on it.
      EXPECT_FALSE(on.keep[i][k] && !off.keep[i][k]) << "frame " << i << " keypoint " << k;
      if (on.keep[i][k] || !off.keep[i][k]) continue;
      ++extra;
      const cv::KeyPoint& kp = on.keypoints[i][k];
      ASSERT_GT(kp.octave, 0);
      ASSERT_FALSE(on.masks[i].empty());
      const float reach =
          static_cast<float>(3.0 * std::pow(f, kp.octave) - options.region_dilate_px);
      ASSERT_GT(reach, 0.f);
      EXPECT_FALSE(MaskWithinRadius(on.masks[i], kp.pt, 0.f));
      EXPECT_TRUE(MaskWithinRadius(on.masks[i], kp.pt, reach));
    }
    ASSERT_EQ(off.masks[i].empty(), on.masks[i].empty());
    if (!off.masks[i].empty()) {
      EXPECT_EQ(cv::countNonZero(off.masks[i] != on.masks[i]), 0);
    }
  }
  EXPECT_GT(extra, 0) << "the clip's people should have coarse corners next to their regions";
  std::printf("octave reach: %d more removals; tp %lld -> %lld, fp %lld -> %lld\n", extra, off.tp,
              on.tp, off.fp, on.fp);
}

// What the lone-seed / lone-suspect options may change: which flagged keypoints are kept, never the
// cues (a kept flagged keypoint still counts as removed for the next frame's ego-motion prior, so
// every frame's cue bits stay the same).
TEST_F(FastFilterSequence, LoneSeedAndSuspectRulesOnlyKeepFlaggedKeypointsOutsideRegions) {
  FastOptions remove_all;  // the rules before session 24: every flagged keypoint is removed
  remove_all.remove_lone_seeds = true;
  const Result all = Run(remove_all);
  FastOptions options = remove_all;
  options.remove_lone_seeds = false;
  options.lone_seed_persistent_px = 0.0;
  const Result seeds_kept = Run(options);
  options.lone_seed_persistent_px = 4.0;
  const Result persistent = Run(options);
  options = remove_all;
  options.lone_suspect_max_age = 0;
  const Result suspect_kept = Run(options);
  options.lone_suspect_max_age = 1;
  const Result suspect_recent = Run(options);
  auto lone_seed = [](uint16_t b) {
    return (b & (kCueSeed | kCueTrack)) && !(b & (kCueRegion | kCueSuspect));
  };
  auto lone_suspect = [](uint16_t b) {
    return (b & kCueSuspect) && !(b & (kCueSeed | kCueTrack | kCueRegion));
  };
  int kept_seeds = 0, persistent_removed = 0, kept_suspect = 0, recent_removed = 0;
  for (const Result* r : {&seeds_kept, &persistent, &suspect_kept, &suspect_recent}) {
    ASSERT_EQ(r->bits, all.bits);
  }
  for (size_t i = 0; i < all.keep.size(); ++i) {
    for (size_t k = 0; k < all.keep[i].size(); ++k) {
      const uint16_t b = all.bits[i][k];
      const bool removed = !all.keep[i][k];
      // Only lone seeds are kept, all of them, and persistence removes a subset of them again.
      EXPECT_EQ(!seeds_kept.keep[i][k], removed && !lone_seed(b)) << i << " " << k;
      EXPECT_TRUE(persistent.keep[i][k] ? seeds_kept.keep[i][k] : removed) << i << " " << k;
      kept_seeds += removed && seeds_kept.keep[i][k];
      persistent_removed += lone_seed(b) && !persistent.keep[i][k];
      // Likewise the keypoints flagged by the suspect map alone.
      EXPECT_EQ(!suspect_kept.keep[i][k], removed && !lone_suspect(b)) << i << " " << k;
      EXPECT_TRUE(suspect_recent.keep[i][k] ? suspect_kept.keep[i][k] : removed) << i << " " << k;
      kept_suspect += removed && suspect_kept.keep[i][k];
      recent_removed += lone_suspect(b) && !suspect_recent.keep[i][k];
    }
  }
  std::printf(
      "lone seeds kept %d (persistent, removed again: %d); lone suspect kept %d (age 1: %d)\n",
      kept_seeds, persistent_removed, kept_suspect, recent_removed);
  // The clip must exercise every rule, both ways.
  EXPECT_GT(kept_seeds, persistent_removed);
  EXPECT_GT(persistent_removed, 0);
  EXPECT_GT(kept_suspect, recent_removed);
  EXPECT_GT(recent_removed, 0);
  options = FastOptions();
  options.lone_seed_persistent_px = -1.0;
  EXPECT_THROW(options.Validate(), InputError);
  options = FastOptions();
  options.lone_suspect_max_age = 31;
  EXPECT_THROW(options.Validate(), InputError);
  options = FastOptions();
  options.lk_window_px = 2147483647;  // an LK window of 2^31 px: std::bad_array_new_length before
  EXPECT_THROW(options.Validate(), InputError);
  options.lk_window_px = 101;
  EXPECT_NO_THROW(options.Validate());
}

TEST_F(FastFilterSequence, MaskCoversDetectionsOnlyWhenRegionsRemovedEnough) {
  FastOptions options;
  const Result never = Run(options);  // refill_min_removed_fraction 0: never
  for (bool covers : never.covers) EXPECT_FALSE(covers);
  // A threshold between the clip's smallest and largest removed fraction (among frames with
  // regions) must say yes on some frames and no on others, exactly where the fraction reaches it.
  double lo = 1.0, hi = 0.0;
  for (const FastFrameInfo& info : never.info) {
    if (info.num_regions == 0) continue;
    const double fraction = static_cast<double>(info.num_removed) / info.num_keypoints;
    lo = std::min(lo, fraction), hi = std::max(hi, fraction);
  }
  ASSERT_LT(lo, hi) << "the clip should have frames with regions removing different fractions";
  options.refill_min_removed_fraction = 0.5 * (lo + hi);
  const Result some = Run(options);
  EXPECT_EQ(some.keep, never.keep);  // the option only answers the System's question
  int yes = 0, no = 0;
  for (size_t i = 0; i < some.info.size(); ++i) {
    const FastFrameInfo& info = some.info[i];
    const bool expected =
        info.num_regions > 0 &&
        info.num_removed >= options.refill_min_removed_fraction * info.num_keypoints;
    EXPECT_EQ(some.covers[i], expected) << "frame " << i;
    (some.covers[i] ? yes : no)++;
  }
  EXPECT_GT(yes, 0);
  EXPECT_GT(no, 0);
  options.refill_min_removed_fraction = 1.5;
  EXPECT_THROW(options.Validate(), InputError);
}

TEST_F(FastFilterSequence, DescriptorCorrespondencesWork) {
  FastOptions options;
  options.correspondences = "descriptors";
  const Result r = Run(options);
  std::printf("descriptors: tp %lld fp %lld fn %lld precision %.3f recall %.3f\n", r.tp, r.fp, r.fn, r.precision(),
              r.recall());
  // Regression floor (measured recall 0.16 on this 24-frame clip with a new region needing 3
  // seeds, 0.27 with 2 before session 33; its precision, 0.08-0.14, is no better than removing
  // keypoints at random here — matched keypoint positions are only as precise as their pyramid
  // level; over 300 frames it does better, docs/fast_mode.md). The path runs and is deterministic.
  EXPECT_GE(r.recall(), 0.12);
  const Result again = Run(options);
  EXPECT_EQ(r.keep, again.keep);
}

TEST_F(FastFilterSequence, BetweenAnalysesTheSuspectMapIsCarried) {
  FastOptions options;
  options.analyse_every = 2;  // frames 0, 2, 4, ... analysed; 1, 3, 5, ... carried
  const Result r = Run(options);
  // Counts over the carried frames and over the analysed ones (objects moving at the frame).
  long long tp[2] = {0, 0}, fp[2] = {0, 0}, fn[2] = {0, 0};
  for (size_t i = 1; i < r.keep.size(); ++i) {
    const ClipFrame& f = clip_->frames[i];
    const int carried = i % 2;
    if (carried) {
      EXPECT_EQ(r.info[i].num_tracked, 0) << "frame " << i << ": nothing but the carry runs";
      for (uint16_t b : r.bits[i]) EXPECT_TRUE(b == 0 || b == kCueSuspect) << "frame " << i;
    } else {
      EXPECT_GT(r.info[i].num_tracked, 100) << "frame " << i;
    }
    for (size_t k = 0; k < r.keypoints[i].size(); ++k) {
      const cv::Point p = KeypointPixel(r.keypoints[i][k], f.mask.size());
      if (f.still.at<uint8_t>(p) != 0) continue;
      const bool truth = f.mask.at<uint8_t>(p) != 0, removed = !r.keep[i][k];
      tp[carried] += truth && removed;
      fp[carried] += !truth && removed;
      fn[carried] += truth && !removed;
    }
  }
  // Frame 1 comes before any judged frame: nothing to carry, every keypoint kept, not judged.
  EXPECT_EQ(std::count(r.keep[1].begin(), r.keep[1].end(), false), 0);
  EXPECT_FALSE(r.judged[0]);
  EXPECT_FALSE(r.judged[1]);
  for (size_t i = 2; i < r.judged.size(); ++i) EXPECT_TRUE(r.judged[i]) << "frame " << i;
  // An analysed frame tracks into the carried frame before it, not into the analysed one two
  // frames back: its tracked points land on that frame's keypoints.
  const auto landing = [&](size_t i, size_t on) {
    int near = 0, tracked = 0;
    for (size_t k = 0; k < r.previous[i].size(); ++k) {
      if (!r.tracked[i][k]) continue;
      ++tracked;
      for (const cv::KeyPoint& kp : r.keypoints[on]) {
        const cv::Point2f d = kp.pt - r.previous[i][k];
        if (d.x * d.x + d.y * d.y <= 0.25f) {
          ++near;
          break;
        }
      }
    }
    return static_cast<double>(near) / std::max(1, tracked);
  };
  double on_carried = 0.0, on_analysed = 0.0;
  for (size_t i = 4; i < r.keep.size(); i += 2) {
    on_carried += landing(i, i - 1);
    on_analysed += landing(i, i - 2);
  }
  // (Session 41: 0.24-0.35 of a frame's tracked points within 0.5 px of a keypoint of the carried
  // frame, 0.06-0.19 of the analysed frame two back.)
  std::printf(
      "tracked points on the carried frame's keypoints: %.2f, on the analysed one's: %.2f\n",
      on_carried / 10, on_analysed / 10);
  EXPECT_GT(on_carried, 1.5 * on_analysed);
  for (int c : {0, 1}) {
    const double precision = static_cast<double>(tp[c]) / std::max(1LL, tp[c] + fp[c]);
    const double recall = static_cast<double>(tp[c]) / std::max(1LL, tp[c] + fn[c]);
    std::printf("%s frames: tp %lld fp %lld fn %lld precision %.3f recall %.3f\n",
                c ? "carried" : "analysed", tp[c], fp[c], fn[c], precision, recall);
    ASSERT_GT(tp[c] + fn[c], 50);
    // Regression floors (session 41 on this clip: analysed 0.614 / 0.695, carried 0.608 / 0.614;
    // every frame analysed: 0.641 / 0.698, the test above).
    EXPECT_GE(precision, 0.5) << c;
    EXPECT_GE(recall, 0.55) << c;
  }
  EXPECT_EQ(Run(options).keep, r.keep);  // deterministic
  options.analyse_every = 0;
  EXPECT_THROW(options.Validate(), InputError);
  options.analyse_every = 2;
  options.suspect_frames = 0;  // nothing to carry
  EXPECT_THROW(options.Validate(), InputError);
}

TEST(FastFilter, FirstFrameKeepsEverythingAndOptionsValidate) {
  PinholeCamera camera;
  camera.fx = camera.fy = 500;
  camera.cx = 160;
  camera.cy = 120;
  camera.width = 320;
  camera.height = 240;
  FastFilter filter(FastOptions(), camera);
  cv::Mat gray(240, 320, CV_8U);
  cv::randu(gray, 0, 255);
  cv::Mat bgr, depth(240, 320, CV_32F, cv::Scalar(2.f));
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  const KeypointSet set = OrbExtractor().Detect(gray);
  FilterInput input;
  input.bgr = &bgr;
  input.gray = &gray;
  input.depth_m = &depth;
  input.keypoints = &set;
  input.want_overlay = true;
  const FilterOutput first = filter.Filter(input);
  EXPECT_EQ(std::count(first.keep.begin(), first.keep.end(), true), set.size());
  EXPECT_FALSE(first.judged);  // No previous frame: no evidence.
  // The same image again (no motion at all): nothing is dynamic.
  const FilterOutput second = filter.Filter(input);
  EXPECT_EQ(std::count(second.keep.begin(), second.keep.end(), true), set.size());
  EXPECT_TRUE(second.judged);
  EXPECT_EQ(second.overlay.size(), bgr.size());
  EXPECT_GT(filter.timing().total_ms, 0.0);
  FastOptions bad;
  bad.correspondences = "sift";
  EXPECT_ANY_THROW(bad.Validate());
  bad = FastOptions();
  bad.epi_t2_px = 0.5;
  EXPECT_ANY_THROW(bad.Validate());
  bad = FastOptions();
  bad.lk_epsilon_px = 0.0;
  EXPECT_ANY_THROW(bad.Validate());
  // The base-image window: odd, >= 5, not above lk_window_px; 0 = lk_window_px.
  FastOptions window;
  for (int px : {0, 5, 11, 21}) {
    window.lk_base_window_px = px;
    EXPECT_NO_THROW(window.Validate()) << px;
  }
  for (int px : {-1, 3, 10, 23}) {
    window.lk_base_window_px = px;
    EXPECT_ANY_THROW(window.Validate()) << px;
  }
  FastOptions gate;
  gate.ego_skip_search_gate_px = -0.1;
  EXPECT_ANY_THROW(gate.Validate());
  gate.ego_skip_search_gate_px = 0.0;  // always search
  EXPECT_NO_THROW(gate.Validate());
}

}  // namespace
}  // namespace dynorb
