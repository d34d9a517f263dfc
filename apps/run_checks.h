// Plausibility checks of a `dynorb run`: warnings for input that reads without error but cannot
// be right (a depth scale off by orders of magnitude, no depth at all) and for a run whose map was
// never initialised, each saying what to check. Reported in stats.json ("warnings") and after the
// run's summary; the run itself is not stopped (a scene may be unusual, the outputs still say
// what happened).
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "dynorb/system/system.h"

namespace dynorb {

// The depth scale of the first frames: per frame the median of the valid depths (> 0, finite)
// of every 8th pixel of every 8th row. (Its cost, ~30 us per frame for the first 30 frames, is
// inside the run's timed loop.)
class DepthScaleCheck {
 public:
  static constexpr int kFramesChecked = 30;

  // depth_m: CV_32FC1 metres (0 = none). Frames after the first kFramesChecked are ignored.
  void Add(const cv::Mat& depth_m);

  int frames_seen() const { return frames_seen_; }
  int frames_with_depth() const { return static_cast<int>(medians_m_.size()); }
  // Median of the per-frame medians; 0 when no frame had depth.
  double median_depth_m() const;

 private:
  int frames_seen_ = 0;
  std::vector<double> medians_m_;
};

struct RunCheckLimits {
  // A median depth outside this range is not what an RGB-D camera sees (Kinect-like sensors:
  // about 0.3-10 m): the depth scale is most likely wrong.
  double min_median_depth_m = 0.1;
  double max_median_depth_m = 15.0;
  double depth_map_factor = 5000.0;  // The configured raw units per metre (for the message).
  int min_init_points = 500;         // TrackerOptions: what initialising the map needs.
  int min_init_depth_points = 100;
  size_t first_frame = 0;  // Dataset index of the run's first frame (--frames A:B): frame numbers
                           // in the messages are the dataset's.
};

// The warnings for this run (empty: nothing implausible).
std::vector<std::string> RunWarnings(const DepthScaleCheck& depth,
                                     const std::vector<FrameRecord>& records,
                                     const RunCheckLimits& limits);

}  // namespace dynorb
