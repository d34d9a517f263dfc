// Region growing for the FAST dynamic mode: moving keypoints (seeds) are grown into pixel
// regions over the depth image, so that every keypoint on a mover is removed, including those
// no cue fired on, and a temporal "suspect" map that keeps recent dynamic regions for a few
// frames (ego-motion compensated, only where the depth still matches).
//
// GrowRegions works on a 1/scale nearest-neighbour copy of the depth map. From each seed it
// flood-fills 4-connected pixels whose depth steps by less than edge_abs + edge_rel·z to their
// neighbour (no depth discontinuity) and stays within band_m of the seed's depth (stops a person
// from leaking into the floor they stand on). A region is dynamic when it holds at least
// min_seeds seeds (1 when it overlaps the suspect map) whose own motions agree (coherence
// |Σ m| / Σ |m| ≥ min_coherence, or many seeds), its static/(static + seed) ratio of confidently
// static tracked points is at most max_static_ratio and its area is at most max_area of the image. The dynamic low-resolution mask is upsampled and dilated.
// Pure functions; thread-safe.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "dynorb/core/pinhole_camera.h"
#include "dynorb/core/rigid3.h"

namespace dynorb {

struct RegionOptions {
  int scale = 4;
  double edge_abs_m = 0.04;
  double edge_rel = 0.03;
  double band_m = 0.45;
  int min_seeds = 2;
  double max_static_ratio = 0.92;
  double min_coherence = 0.6;  // |mean seed motion| / mean |seed motion| (a rigid part moves as one)
  int coherent_free_seeds = 6; // this many seeds need no coherence
  double max_area = 0.8;
  int dilate_px = 6;
  float max_depth_m = 8.f;
};

struct RegionPoint {
  cv::Point2f pixel;   // full-resolution pixel
  float depth_m = 0.f; // its depth (0 = none)
  cv::Point2f motion;  // seeds: own image motion (tracked minus rigid-warp prediction, px)
};

struct RegionResult {
  cv::Mat low_mask;   // CV_8U, 1/scale, 255 = dynamic (undilated)
  cv::Mat mask;       // CV_8U, full resolution, 255 = dynamic (dilated)
  int num_regions = 0, num_accepted = 0;
};

// Nearest-neighbour 1/scale copy of a depth map (pixel centres x·scale + scale/2); depths outside
// (0, max_depth_m] become 0.
cv::Mat DownsampleDepth(const cv::Mat& depth_m, int scale, float max_depth_m);

// The full-resolution mask of a 1/scale mask: nearest-neighbour upsampling (each low pixel a
// scale×scale block, cropped to full_size), then dilation with an elliptic disc of radius
// dilate_px (0: none). Works only inside the bounding box of the set pixels (grown by the radius):
// the same result as upsampling and dilating the whole image, at a fraction of the cost.
cv::Mat UpsampleAndDilate(const cv::Mat& low_mask, int scale, cv::Size full_size, int dilate_px);

// True when a set pixel of mask (CV_8U) lies within radius_px of pixel (Euclidean, pixel centres;
// radius 0: the pixel itself). Pixels outside the image do not count.
bool MaskWithinRadius(const cv::Mat& mask, cv::Point2f pixel, float radius_px);

// low_depth: DownsampleDepth(depth, options.scale, ...); full_size: the image size.
// suspect_low: CV_8U at 1/scale (255 = suspect), or empty.
RegionResult GrowRegions(const cv::Mat& low_depth, cv::Size full_size, const std::vector<RegionPoint>& seeds,
                         const std::vector<RegionPoint>& statics, const cv::Mat& suspect_low,
                         const RegionOptions& options);

// The temporal suspect map at 1/scale: a pixel of the current frame is suspect when it warps
// (ego-motion, its current depth) onto a previous suspect pixel of age < max_age whose recorded
// depth matches the warped depth within depth_tol_m; it then gets age + 1. Pixels of the current
// dynamic mask get age 0 and their depth. age: CV_8U (255 = none), depth: CV_32F.
struct SuspectMap {
  cv::Mat age, depth;
  bool empty() const { return age.empty(); }
  cv::Mat Suspect(int max_age) const;  // CV_8U 255 where age <= max_age
};
SuspectMap PropagateSuspect(const SuspectMap& previous, const cv::Mat& low_depth_cur, const PinholeCamera& camera,
                            int scale, const Rigid3d& prev_from_cur, int max_age, double depth_tol_m);
void AddToSuspect(const cv::Mat& low_mask, const cv::Mat& low_depth, SuspectMap* map);

}  // namespace dynorb
