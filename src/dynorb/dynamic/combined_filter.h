// CombinedFilter: several KeypointFilters applied to the same frame, a keypoint is kept only if
// every filter keeps it. `dynorb run --mode fused` combines the semantic detector masks (they
// catch a person who is momentarily still) with the FAST geometric cues (they catch movers the
// detector does not know, such as a pushed box).
// Dynamic masks are OR-ed; the frame is judged when any part judged it; overlays are composed
// (each filter's drawing over the first's);
// stage timings are prefixed with the part's label ("semantic.detector", "fast.flow", ...).
// Every part sees the full frame and all keypoints, so each keeps its own temporal state.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "dynorb/dynamic/keypoint_filter.h"

namespace dynorb {

class CombinedFilter : public KeypointFilter {
 public:
  struct Part {
    std::string label;
    std::unique_ptr<KeypointFilter> filter;
    // Count this part's removals only where its dynamic mask is set (drops isolated votes).
    bool only_inside_mask = false;
    // When this part alone would remove more than this fraction of the keypoints the earlier
    // parts kept, its evidence is distrusted for the frame: its removals and its mask are dropped
    // (geometric cues that fail under fast rotation flag most of the static scene; losing the
    // track costs more than a missed mover). 1 = never distrusted.
    double max_removed_fraction = 1.0;
    // A connected region of this part's dynamic mask lying more than this fraction inside the
    // earlier parts' mask is left to them: the region is dropped from this part's mask, so with
    // only_inside_mask its removals do not count (the detector's mask already covers that mover;
    // the geometric region around it mostly adds static outline keypoints). 1 = never.
    double max_overlap_with_earlier = 1.0;
  };
  // Throws std::invalid_argument when empty. allow_refill: MaskCoversDetections() is true when
  // every part either covers its detections itself or counts only inside its mask.
  explicit CombinedFilter(std::vector<Part> parts, bool allow_refill = false);
  // The connected regions of `mask` (CV_8U, nonzero = set) with at most `max_fraction` of their
  // pixels inside `earlier` (same size; empty: no overlap), as a 0/255 mask.
  static cv::Mat RegionsMostlyOutside(const cv::Mat& mask, const cv::Mat& earlier, double max_fraction);

  std::string name() const override;
  FilterOutput Filter(const FilterInput& input) override;
  std::vector<std::pair<std::string, double>> StageTimings() const override;
  // Every part's cues, prefixed with its label ("fast.residual", ...).
  std::vector<std::pair<std::string, std::vector<bool>>> CueFlags() const override;
  bool MaskCoversDetections() const override;
  // Without allow_refill, MaskCoversDetections() is false even when every part counts only inside its mask: a
  // refill outside the fused mask puts keypoints back on movers the geometric part missed.
  // Measured (300 frames, 2026-11-30): walking_rpy 14.2 -> 32.4 mm, walking_static 4.9 -> 6.0 mm.
  // Frames on which part `index` was distrusted (Part::max_removed_fraction).
  int distrusted_frames(size_t index) const { return distrusted_.at(index); }

 private:
  std::vector<Part> parts_;
  bool allow_refill_ = false;
  std::vector<double> part_ms_;
  std::vector<int> distrusted_;
};

}  // namespace dynorb
