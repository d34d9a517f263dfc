// SemanticFilter: the KeypointFilter of `dynorb run --mode semantic`. A MaskProvider (a DNN
// detector by default) gives a-priori dynamic objects on scheduled frames; keypoints inside the
// dynamic mask are rejected before description.
//
// Schedule (deterministic): the provider runs on frames with frame_id % detect_every == 0. On the
// frames in between, each object's box is carried by the median pyramidal Lucas-Kanade flow of
// points sampled in its mask (as NGD-SLAM carries masks between detections), then re-refined
// with the current depth around the object's carried depth. Objects older than
// max_carried_frames are dropped. Called from the tracking thread only.
// Fewer detections: after quiet_after_empty detections in a row found no dynamic object, only
// every quiet_detect_every-th frame is detected; after steady_after detections in a row agreed
// with the carried objects (as many objects, paired one to one at IoU >= steady_min_iou; inline,
// the objects as carried to the previous frame, pipelined, to the detected frame), only every
// steady_detect_every-th. Both depend on the images only, never on timing: deterministic.
// With detector_latency L > 0 the provider runs on a worker thread: the detection of frame k is
// started at frame k and used at frame k + L (carried by flow from frame k), so the detector
// overlaps tracking on a second core while the schedule stays deterministic.
#pragma once

#include <future>
#include <memory>
#include <string>
#include <vector>

#include "dynorb/dynamic/detector_dnn.h"
#include "dynorb/dynamic/keypoint_filter.h"
#include "dynorb/dynamic/mask_provider.h"
#include "dynorb/dynamic/mask_refine.h"

namespace dynorb {

// Default a-priori dynamic classes: person, vehicles and the COCO animals.
std::vector<std::string> DefaultDynamicClasses();
// Class ids of `model_names` that are in `wanted` (aliases: motorcycle=motorbike,
// airplane=aeroplane, couch=sofa, tv=tvmonitor). A wanted name that is no COCO class is an
// InputError naming it and listing the valid names.
std::vector<bool> ResolveDynamicClasses(const std::vector<std::string>& wanted,
                                        const std::vector<std::string>& model_names);

struct SemanticOptions {
  DetectorOptions detector;                               // model, models_dir, thresholds
  std::vector<std::string> classes = DefaultDynamicClasses();  // a-priori dynamic classes
  int detect_every = 4;         // run the provider on every Nth frame (>= 1), carry masks between
  int detector_latency = 0;     // 0: detect inline; L > 0: detect on a worker thread, use the
                                // result L frames later (carried by flow), L < detect_every
  int max_carried_frames = 15;  // drop carried objects after this many frames without detection
  int quiet_detect_every = 0;   // 0: off; else a multiple of detect_every, the schedule after
  int quiet_after_empty = 2;    // this many detections in a row without a dynamic object
  int steady_detect_every = 0;  // 0: off; else a multiple of detect_every, the schedule after
  int steady_after = 2;         // this many detections in a row that agreed with the carried
  double steady_min_iou = 0.7;  // objects: as many, paired one to one at this IoU or more
                                // (steady_detect_every + detector_latency - 1 must be at most
                                // max_carried_frames)
  int carry_grid = 4;           // carrying tracks up to carry_grid^2 points per object (LK;
                                // session 34: 4 instead of 8, 0.2 ms less, same accuracy)
  int carry_downscale = 2;      // carrying tracks on images downscaled by 1 (full resolution) or
                                // 2 (pyrDown; LK window 11 over 2 levels instead of 21 over 3)
  DepthRefineOptions refine;    // box -> mask with depth
  void Validate() const;
};

// `options` for a provider that has every frame (mask or box files, the oracle): every frame is
// asked, inline, with the quiet and steady schedules off (they would leave frames unread whose
// masks the file has: a mask file gives no objects, so every read looks empty to them).
SemanticOptions EveryFrameSchedule(SemanticOptions options);

// options.detector asked for options.classes only (spelled as the models' names files spell
// them): a box takes the best-scoring dynamic class, and a darknet model runs with its heads cut
// to those classes (DetectorOptions::prune_heads).
DetectorOptions SemanticDetectorOptions(const SemanticOptions& options);

// Detector-backed provider: DnnDetector (asked for the dynamic classes only) + depth refinement.
class DetectorMaskProvider : public MaskProvider {
 public:
  DetectorMaskProvider(const SemanticOptions& options);
  std::string name() const override { return "detector:" + detector_.spec().name; }
  DynamicObjects Masks(const MaskQuery& query) override;
  const DnnDetector& detector() const { return detector_; }

 private:
  SemanticOptions options_;
  DnnDetector detector_;
};

class SemanticFilter : public KeypointFilter {
 public:
  SemanticFilter(std::unique_ptr<MaskProvider> provider, const SemanticOptions& options);
  std::string name() const override { return "semantic(" + provider_->name() + ")"; }
  FilterOutput Filter(const FilterInput& input) override;
  bool MaskCoversDetections() const override { return true; }  // Masks are the whole decision.
  // "detector" (the provider, on scheduled frames) and "propagation" (carrying masks between).
  std::vector<std::pair<std::string, double>> StageTimings() const override {
    return {{"detector", provider_ms_}, {"detector_wait", wait_ms_}, {"propagation", propagation_ms_}};
  }

  // Per-stage timing of the last frame.
  double last_provider_ms() const { return provider_ms_; }
  double last_propagation_ms() const { return propagation_ms_; }
  bool last_was_detection() const { return last_was_detection_; }
  const DynamicObjects& current() const { return current_; }

 private:
  // `from` (the objects on `from_small`) moved to `small` by the median LK flow of each object;
  // both images are the frames' grey images (of size `full`) downscaled by carry_downscale
  // (Downscaled()).
  DynamicObjects Carry(const DynamicObjects& from, const cv::Mat& from_small, const cv::Mat& small,
                       cv::Size full, const cv::Mat& depth_m) const;
  cv::Mat Downscaled(const cv::Mat& gray) const;
  // Whether frame `frame_id` is scheduled for a detection (detect_every, quiet_detect_every,
  // steady_detect_every).
  bool Scheduled(FrameId frame_id) const;
  // Updates empty_detections_ and steady_detections_ from a detection and the objects carried to
  // (about) the same frame.
  void CountDetection(const DynamicObjects& detected, const std::vector<DynamicObject>& carried);
  // Waits for the detection in flight and discards it.
  void DropPending();

  std::unique_ptr<MaskProvider> provider_;
  SemanticOptions options_;
  DynamicObjects current_;
  cv::Mat previous_small_;  // The previous frame's grey image, downscaled.
  int frames_since_detection_ = 0;
  int empty_detections_ = 0;   // Detections in a row that found no dynamic object.
  int steady_detections_ = 0;  // Detections in a row that agreed with the carried objects.
  double provider_ms_ = 0.0, propagation_ms_ = 0.0, wait_ms_ = 0.0;
  bool last_was_detection_ = false;
  // Pipelined detection (detector_latency > 0): at most one in flight. Declared after provider_
  // so that it is destroyed (waiting for the worker) before the provider.
  std::future<DynamicObjects> pending_;
  FrameId pending_frame_ = 0;
  cv::Mat pending_small_;
  std::vector<DynamicObject> pending_carried_;  // The objects carried to the pending frame.
  double pending_provider_ms_ = 0.0;            // Written by the worker before its result is ready.
};

}  // namespace dynorb
