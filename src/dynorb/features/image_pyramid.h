// Image pyramid of the ORB extractor and the per-level scale tables used by the tracker.
//
// Level 0 is (a private copy of) the input; level l is cv::resize(level l-1, INTER_LINEAR) to
// round(W / s^l) × round(H / s^l), as in ORB-SLAM. Levels too small to hold a keypoint (smaller
// than 2·kEdgeThreshold + 1 in a dimension) and all coarser ones are left empty.
//
// Coordinates: pixel centres at integers (OpenCV convention). cv::resize maps a level-l pixel
// centre x_l to full resolution exactly as x_0 = (x_l + 0.5)·(W_0 / W_l) − 0.5 (per axis; the
// actual rounded size ratio, not the nominal s^l). LevelToFull / FullToLevel implement that.
//
// Immutable after construction; safe to share between threads (KeypointSet holds a shared_ptr).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace dynorb {

constexpr int kEdgeThreshold = 19;  // keypoints lie at least this many pixels inside every level
constexpr int kPatchSize = 31;      // diameter of the orientation / descriptor patch
constexpr int kHalfPatchSize = 15;  // radius of the intensity-centroid disc

// Nominal scale tables of a pyramid: scale[l] = scale_factor^l, sigma2[l] = scale[l]² (the
// variance factor of a measurement at level l, as in ORB-SLAM).
struct ScaleLevels {
  ScaleLevels() = default;
  ScaleLevels(int n_levels, double scale_factor);

  int NumLevels() const { return static_cast<int>(scale.size()); }

  double scale_factor = 1.2;
  double log_scale_factor = 0.0;   // log(scale_factor), for predicting levels from distances
  std::vector<double> scale;       // s^l
  std::vector<double> inv_scale;   // s^-l
  std::vector<double> sigma2;      // s^2l
  std::vector<double> inv_sigma2;  // s^-2l
};

class ImagePyramid {
 public:
  // image: CV_8UC1, non-empty (checked by the caller). Copies the image.
  ImagePyramid(const cv::Mat& image, const ScaleLevels& levels);

  int NumLevels() const { return static_cast<int>(levels_.size()); }
  const cv::Mat& Level(int l) const { return levels_[l]; }
  bool LevelUsable(int l) const { return !levels_[l].empty(); }
  cv::Size FullSize() const { return full_size_; }

  // Exact level ↔ full-resolution coordinate maps (see the file comment).
  cv::Point2f LevelToFull(int l, cv::Point2f p_level) const;
  cv::Point2f FullToLevel(int l, cv::Point2f p_full) const;

 private:
  cv::Size full_size_;
  std::vector<cv::Mat> levels_;
  std::vector<cv::Point2d> full_from_level_;  // (W_0 / W_l, H_0 / H_l)
};

}  // namespace dynorb
