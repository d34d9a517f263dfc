// Ground truth of moving objects for `dynorb run`: the per-pixel masks of synthetic sequences
// (masks.txt: "timestamp masks/<ts>.png", 8-bit object id, 0 = static), the precision/recall of
// the keypoints a mode labels dynamic, and the overlay images of --save-overlays.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "dynorb/io/association.h"
#include "dynorb/tracking/dynamic_votes.h"

namespace dynorb {

class MaskGroundTruth {
 public:
  // Nothing when the folder has no masks.txt. Throws InputError for a malformed masks.txt.
  // image_size: the size every mask must have (the images'; empty: not checked).
  static std::optional<MaskGroundTruth> Open(const std::string& dataset, cv::Size image_size = {});
  // The mask whose stamp is within 5 ms of `timestamp_s` (empty Mat if none). Throws InputError
  // if the listed PNG is missing, not 8-bit single channel, or not of the images' size.
  cv::Mat MaskAt(double timestamp_s) const;
  // The pixels of `mask` (from MaskAt) whose object stands still at `timestamp_s` according to
  // the dataset's objects.txt ("ts id moving ..."), 255 there; empty when the dataset has no
  // objects.txt or every object moves. A person who stops and the desk item before it starts
  // are in the masks but are not moving at that frame.
  cv::Mat StillObjectsAt(const cv::Mat& mask, double timestamp_s) const;
  bool has_object_states() const { return has_objects_file_; }

 private:
  std::string folder_;
  cv::Size image_size_;
  std::vector<StampedPath> masks_;
  bool has_objects_file_ = false;
  std::vector<std::pair<double, std::vector<int>>> still_ids_;  // Per stamp (sorted): still object ids.
};

// The truth about one frame's keypoints against one mask, computed once and then tallied by every
// KeypointLabelStats that counts them (the whole filter, each of its cues).
struct KeypointTruth {
  bool has_mask = false;
  std::vector<uint8_t> ignored;    // centre pixel on `ignore`: not counted
  std::vector<uint8_t> on_object;  // centre pixel on a (not ignored) object
  std::vector<uint8_t> object_id;  // that object's id in the mask (0 when not on_object)
  std::vector<uint8_t> support;    // on_object, or its FAST circle at its level touches one
  std::vector<uint8_t> near;       // within KeypointLabelStats::kBoundaryPx of one (7x7 ellipse)
};
// mask empty: has_mask = false (nothing is counted). ignore (optional, CV_8U): see Add below.
KeypointTruth ComputeKeypointTruth(const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& mask,
                                   const cv::Mat& ignore, double level_scale_factor);

// Counts over keypoints: positive = labelled dynamic (removed); truth = on a moving-object pixel.
// The recall is also kept per object id of the mask (`by_object`), so that a small mover (the
// synthetic sequences' pushed box, id 4, and desk item, id 5) is not hidden in the people's totals.
// A second, scale-aware truth ("support") also counts a keypoint as on the object when its FAST
// circle at its own pyramid level (radius 3 px there, 3·scale^octave px in the image) touches the
// object: such a corner is the object's outline and moves with it. Its precision AND recall are
// reported (the outline keypoints a filter keeps are misses there).
class KeypointLabelStats {
 public:
  // level_scale_factor: the ORB pyramid's scale factor (keypoint octave -> image scale).
  explicit KeypointLabelStats(double level_scale_factor) : level_scale_factor_(level_scale_factor) {}
  // keep: per keypoint, true = kept as static (empty = all kept, e.g. plain mode).
  // ignore (optional, CV_8U): keypoints on its non-zero pixels are not counted at all.
  void Add(const std::vector<cv::KeyPoint>& keypoints, const std::vector<bool>& keep, const cv::Mat& mask,
           const cv::Mat& ignore = cv::Mat());
  // The same with the truth computed beforehand (ComputeKeypointTruth with this level scale).
  void Add(const KeypointTruth& truth, const std::vector<bool>& keep);
  nlohmann::json ToJson() const;

  // A removed keypoint off the object but within this many px of it: its FAST circle (radius 3)
  // touches the object, so its corner may be the object's outline (counted separately).
  static constexpr int kBoundaryPx = 3;

 private:
  double level_scale_factor_;
  long long tp_ = 0, fp_ = 0, fn_ = 0, tn_ = 0, ignored_ = 0, fp_near_ = 0;
  long long support_tp_ = 0, support_fp_ = 0, support_fn_ = 0;
  // Per object id (index = id): keypoints on it removed (tp) and kept (fn), by the centre pixel.
  std::vector<long long> object_tp_ = std::vector<long long>(256, 0),
                         object_fn_ = std::vector<long long>(256, 0);
  std::vector<double> frame_precision_, frame_recall_;
  int frames_ = 0;
};

// How many of `keypoints` lie on a moving object of `mask` that `ignore` (optional) does not cover:
// `pixel` by their centre pixel, `support` also when their FAST circle touches one (see above).
struct KeypointsOnObjects {
  int pixel = 0;
  int support = 0;
};
KeypointsOnObjects CountOnObjects(const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& mask,
                                  const cv::Mat& ignore, double level_scale_factor);

// Of landmark origins (LandmarkOrigin, landmark_summary.h), those known and with a mask at their
// stamp (with_origin) and, of them, those whose keypoint at the origin lay (centre pixel) on an
// object of the masks (made_on_objects). object_id[i]: that object's id in the mask (0: none, or
// not judged), one entry per origin; by_object: the count per id.
struct OriginTruth {
  long long with_origin = 0;
  long long made_on_objects = 0;
  std::vector<uint8_t> object_id;
  std::map<int, long long> by_object;
};
OriginTruth ClassifyOrigins(const std::vector<LandmarkOrigin>& origins,
                            const MaskGroundTruth& masks);
// The same for the landmarks the tracker erased as dynamic (ErasedLandmark).
OriginTruth ClassifyErasedLandmarks(const std::vector<ErasedLandmark>& erased,
                                    const MaskGroundTruth& masks);

// Draws kept keypoints green and removed ones red on `base` (the filter's overlay, or the image).
cv::Mat DrawKeypointOverlay(const cv::Mat& base, const std::vector<cv::KeyPoint>& keypoints,
                            const std::vector<bool>& keep);

}  // namespace dynorb
