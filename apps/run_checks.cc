#include "run_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dynorb {
namespace {

constexpr int kSampleStep = 8;

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

std::string Format(const char* format, double a, double b = 0.0, double c = 0.0) {
  char text[128];
  std::snprintf(text, sizeof(text), format, a, b, c);
  return text;
}

}  // namespace

void DepthScaleCheck::Add(const cv::Mat& depth_m) {
  if (frames_seen_ >= kFramesChecked) return;
  ++frames_seen_;
  if (depth_m.empty() || depth_m.type() != CV_32FC1) return;
  std::vector<double> samples;
  samples.reserve(static_cast<size_t>(depth_m.rows / kSampleStep + 1) *
                  (depth_m.cols / kSampleStep + 1));
  for (int y = 0; y < depth_m.rows; y += kSampleStep) {
    const float* row = depth_m.ptr<float>(y);
    for (int x = 0; x < depth_m.cols; x += kSampleStep) {
      if (row[x] > 0.0f && std::isfinite(row[x])) samples.push_back(row[x]);
    }
  }
  if (!samples.empty()) medians_m_.push_back(Median(std::move(samples)));
}

double DepthScaleCheck::median_depth_m() const { return Median(medians_m_); }

std::vector<std::string> RunWarnings(const DepthScaleCheck& depth,
                                     const std::vector<FrameRecord>& records,
                                     const RunCheckLimits& limits) {
  std::vector<std::string> warnings;
  const std::string first_frames = "the first " + std::to_string(depth.frames_seen()) + " frames";
  const std::string factor_hint =
      "check DepthMapFactor (raw depth units per metre: 5000 for TUM RGB-D, Bonn and "
      "dynorb synth, 1000 for millimetre PNGs; now " +
      Format("%g", limits.depth_map_factor) + ")";
  if (depth.frames_seen() > 0 && depth.frames_with_depth() == 0) {
    warnings.push_back(
        "no valid depth (> 0) in the sampled pixels of " + first_frames +
        ": RGB-D SLAM needs depth; check that depth.txt (or associations.txt) lists the depth "
        "images and that they are 16-bit PNGs");
  } else if (depth.frames_with_depth() > 0) {
    const double median = depth.median_depth_m();
    if (median > limits.max_median_depth_m || median < limits.min_median_depth_m) {
      warnings.push_back("the depth images read as " + Format("%.3g m", median) +
                         " away (median over " + first_frames +
                         "), where an RGB-D camera sees about 0.3-10 m: " + factor_hint);
    }
  }
  const bool initialised = std::any_of(records.begin(), records.end(), [](const FrameRecord& r) {
    return r.state != TrackingState::kNotInitialized;
  });
  if (!records.empty() && !initialised) {
    // The frame that came closest to the rule: the larger of its two shortfalls is the smallest.
    const auto score = [&](const FrameRecord& r) {
      return std::min(static_cast<double>(r.num_used) / limits.min_init_points,
                      static_cast<double>(r.num_with_depth) / limits.min_init_depth_points);
    };
    const FrameRecord& best = *std::max_element(
        records.begin(), records.end(),
        [&](const FrameRecord& a, const FrameRecord& b) { return score(a) < score(b); });
    std::string keypoint_hint;
    if (best.num_used < limits.min_init_points) {
      if (best.num_keypoints < limits.min_init_points) {
        keypoint_hint =
            "; too few keypoints: blank or textureless images, or "
            "ORBextractor.nFeatures below " +
            std::to_string(limits.min_init_points);
      } else if (!best.judged && best.num_filtered == best.num_keypoints) {
        // A filter that compares each frame with the one before cannot judge the first.
        keypoint_hint = "; the keypoint filter withheld all " + std::to_string(best.num_keypoints) +
                        " of its keypoints: it could not judge the frame (the fast mode compares "
                        "each frame with the one before, so a sequence needs at least two)";
      } else {
        keypoint_hint = "; the keypoint filter removed " + std::to_string(best.num_filtered) +
                        " of its " + std::to_string(best.num_keypoints) + " keypoints";
      }
    }
    // Depth is to blame only when enough keypoints were left to find it on.
    const bool depth_short = best.num_with_depth < limits.min_init_depth_points &&
                             best.num_used >= limits.min_init_depth_points;
    warnings.push_back(
        "the map was never initialised: a frame needs at least " +
        std::to_string(limits.min_init_points) + " keypoints of which " +
        std::to_string(limits.min_init_depth_points) + " with depth; the closest was frame " +
        std::to_string(limits.first_frame + best.id) + Format(" (t = %.6f s)", best.timestamp_s) +
        " with " + std::to_string(best.num_used) + " keypoints, " +
        std::to_string(best.num_with_depth) + " with depth" + keypoint_hint +
        (depth_short ? "; too little depth: check the depth images and DepthMapFactor" : ""));
  }
  return warnings;
}

}  // namespace dynorb
