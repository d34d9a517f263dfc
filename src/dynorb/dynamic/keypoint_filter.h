// KeypointFilter: the hook of the dynamic modes. The System calls it after ORB detection and
// before description, so keypoints it rejects never get descriptors, never reach matching, pose
// optimisation or the map. Implementations: FAST geometric cues, detector masks, file masks, ...
// Called from the tracking thread only, once per frame in order; may keep state between frames.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "dynorb/core/ids.h"
#include "dynorb/core/rigid3.h"
#include "dynorb/features/orb_extractor.h"

namespace dynorb {

struct FilterInput {
  FrameId frame_id = 0;
  double timestamp_s = 0.0;
  const cv::Mat* bgr = nullptr;      // CV_8UC3.
  const cv::Mat* gray = nullptr;     // CV_8UC1, what ORB was detected on.
  const cv::Mat* depth_m = nullptr;  // CV_32F metres, 0 = no depth.
  const KeypointSet* keypoints = nullptr;
  // Motion-model prediction of the camera pose change since the previous frame, when tracking.
  std::optional<Rigid3d> predicted_cam_from_previous_cam;
  // The caller wants FilterOutput::overlay (e.g. `dynorb run --save-overlays`).
  bool want_overlay = false;
};

struct FilterOutput {
  std::vector<bool> keep;  // One flag per keypoint: false = dynamic, removed before description.
  cv::Mat dynamic_mask;    // Optional CV_8U mask (255 = dynamic) for overlays and statistics.
  cv::Mat overlay;         // Optional BGR drawing of the filter's evidence (flow vectors, epipolar
                           // outliers, boxes), only when FilterInput::want_overlay.
  // The removed keypoints the filter saw move on their own (a motion cue, not only a region or a
  // mask around them), current-frame pixels. The tracker lets them vote against the landmarks
  // beside them at their depth (tracking/dynamic_votes.h). Filters without such cues leave it
  // empty.
  std::vector<cv::Point2f> moving_points;
  // False when the filter could not judge this frame (the FAST cues on their first frame: no
  // previous frame). The System does not initialize the map from such a frame: its unjudged
  // keypoints would put the movers into the first keyframe.
  bool judged = true;
  // False when the filter carried its earlier result to this frame instead of analysing it (the
  // FAST cues between analyses: fast.analyse_every, fast.quiet_analyse_every).
  bool analysed = true;
};

class KeypointFilter {
 public:
  virtual ~KeypointFilter() = default;
  virtual std::string name() const = 0;
  virtual FilterOutput Filter(const FilterInput& input) = 0;
  // Milliseconds of each named stage of the last Filter() call (e.g. {"flow", 1.2}), for
  // stats.json's timing_ms.filter_stages. Stages that did not run that frame report 0.
  virtual std::vector<std::pair<std::string, double>> StageTimings() const { return {}; }
  // Per named cue, which keypoints of the last Filter() call it flagged moving (one flag per
  // keypoint), so that `dynorb run` can score every cue against ground-truth masks
  // (stats.json dynamic_keypoints.by_cue). Filters without separate cues return nothing.
  virtual std::vector<std::pair<std::string, std::vector<bool>>> CueFlags() const { return {}; }
  // True when FilterOutput::dynamic_mask covers every moving object the filter found, so that
  // the System may detect again outside it and spend the whole feature budget on the rest
  // (SystemOptions::refill_filtered). Filters whose misses are spread over the image (the FAST
  // cues) should say false: a refill then adds keypoints on the movers they missed.
  virtual bool MaskCoversDetections() const { return false; }
};

}  // namespace dynorb
