// ORB feature extraction as ORB-SLAM does it, split into detection and description so that a
// filter (the dynamic modes) can remove keypoints before descriptors are computed.
//
// Detect(): build the image pyramid (image_pyramid.h); on each level run FAST with
// ini_th_fast inside a border of kEdgeThreshold px, fall back to min_th_fast in the ≈cell_size_px
// cells where it found nothing, keep the level's budget of keypoints with the quadtree
// (quadtree.h), and orient them by intensity centroid. Describe(): 256-bit steered BRIEF on the
// Gaussian-blurred (7×7, σ = 2) level. Algorithm and conventions: docs/features.md.
//
// Keypoint conventions: `pt` in full-resolution pixels at every level (pixel centres at integers:
// x_0 = (x_l + 0.5)·W_0/W_l − 0.5); `octave` = pyramid level; `size` = kPatchSize·scale_factor^l;
// `angle` in degrees [0, 360) (x right, y down); `response` = FAST score; `class_id` = -1.
// Keypoints are ordered by level, then by the quadtree's node order — deterministic.
//
// Threading: an OrbExtractor is immutable after construction; all methods are const and may be
// called concurrently. A KeypointSet shares its pyramid read-only and is cheap to copy.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "dynorb/core/orb_limits.h"
#include "dynorb/features/image_pyramid.h"

namespace dynorb {

struct OrbOptions {
  int n_features = 1000;      // total keypoint budget over all levels
  double scale_factor = 1.2;  // scale ratio between consecutive pyramid levels (> 1)
  int n_levels = 8;           // number of pyramid levels
  int ini_th_fast = 20;       // FAST threshold tried first in every cell
  int min_th_fast = 7;        // FAST threshold in cells where ini_th_fast finds nothing
  int cell_size_px = 30;      // side of the FAST detection cells (level pixels)

  // Throws InputError on out-of-range values.
  void Validate() const;
};

// Keypoints of one image plus the pyramid they were detected on (kept for Describe()).
struct KeypointSet {
  std::vector<cv::KeyPoint> keypoints;  // full-resolution coordinates (see file comment)
  std::vector<cv::Point> level_pixels;  // keypoints[i]'s integer pixel in its level
  std::shared_ptr<const ImagePyramid> pyramid;
  // Per level, every FAST corner found before the quadtree distribution (level coordinates);
  // lets DetectExcluding() redistribute the budget without running FAST again.
  std::shared_ptr<const std::vector<std::vector<cv::KeyPoint>>> candidates;

  int size() const { return static_cast<int>(keypoints.size()); }
};

// Keypoints with their descriptors: descriptors.row(i) (CV_8UC1, kBriefBytes columns) belongs to
// keypoints[i].
struct OrbFeatures {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
};

class OrbExtractor {
 public:
  // Validates the options (throws InputError).
  explicit OrbExtractor(const OrbOptions& options = OrbOptions());

  // image: CV_8UC1, non-empty (throws InputError otherwise).
  KeypointSet Detect(const cv::Mat& image) const;
  // Detects again on `base`'s pyramid, ignoring corners where `exclude` (CV_8UC1, full image
  // size, nonzero = excluded) is set, so each level's whole budget is spread over the rest of the
  // image. Used after a dynamic filter removed keypoints (throws InputError on a bad mask).
  KeypointSet DetectExcluding(const KeypointSet& base, const cv::Mat& exclude) const;

  // Descriptors of set.keypoints[indices[i]] in row i (indices must be valid; may repeat).
  cv::Mat Describe(const KeypointSet& set, const std::vector<int>& indices) const;
  // Descriptors of all keypoints of the set.
  cv::Mat Describe(const KeypointSet& set) const;
  // The keypoints with keep[i] == true and their descriptors; keep.size() must equal set.size().
  OrbFeatures DescribeKept(const KeypointSet& set, const std::vector<bool>& keep) const;

  // Detect() followed by Describe() of every keypoint.
  OrbFeatures DetectAndDescribe(const cv::Mat& image) const;

  const OrbOptions& options() const { return options_; }
  // Nominal per-level scale, inverse scale, sigma² = scale² and inverse sigma².
  const ScaleLevels& levels() const { return levels_; }
  // Keypoint budget of each level: n_features·f^l·(1−f)/(1−f^n_levels), f = 1/scale_factor,
  // rounded, the last level taking the remainder (as ORB-SLAM).
  const std::vector<int>& features_per_level() const { return features_per_level_; }

 private:
  // Keypoints of one level (level pixel coordinates) before orientation.
  // FAST corners of one level (level pixel coordinates, the ORB-SLAM cell fallback included).
  std::vector<cv::KeyPoint> FastCornersOnLevel(const cv::Mat& level, int budget) const;
  // The level's budget of `corners` spread by the quadtree.
  std::vector<cv::KeyPoint> DistributeOnLevel(const cv::Mat& level,
                                              std::vector<cv::KeyPoint> corners, int budget) const;
  // `candidates`: FAST corners per level from an earlier detection (nullptr: run FAST).
  // `oriented`: an earlier detection on the same pyramid (or nullptr); a keypoint it already
  // holds (same level, same level pixel) takes its angle instead of computing it again.
  KeypointSet DetectOnPyramid(
      std::shared_ptr<const ImagePyramid> pyramid, const cv::Mat& exclude,
      std::shared_ptr<const std::vector<std::vector<cv::KeyPoint>>> candidates,
      const KeypointSet* oriented) const;

  OrbOptions options_;
  ScaleLevels levels_;
  std::vector<int> features_per_level_;
};

}  // namespace dynorb
