// CombinedFilter: several KeypointFilters applied to the same frame, a keypoint is kept only if
// every filter keeps it. `dynorb run --mode fused` combines the semantic detector masks (they
// catch a person who is momentarily still) with the FAST geometric cues (they catch movers the
// detector does not know, such as a pushed box).
// Dynamic masks are OR-ed; overlays are composed (each filter's drawing over the first's);
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
  };
  explicit CombinedFilter(std::vector<Part> parts);  // Throws std::invalid_argument when empty.

  std::string name() const override;
  FilterOutput Filter(const FilterInput& input) override;
  std::vector<std::pair<std::string, double>> StageTimings() const override;

 private:
  std::vector<Part> parts_;
  std::vector<double> part_ms_;
};

}  // namespace dynorb
