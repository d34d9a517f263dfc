#include "dynorb/features/orb_extractor.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>

#include "dynorb/core/error.h"
#include "dynorb/features/brief_pattern.h"
#include "dynorb/features/orb_descriptor.h"
#include "dynorb/features/quadtree.h"

namespace dynorb {
namespace {

// Programming-error check (aborts); bad input is reported with InputError instead.
#define DYNORB_FEATURES_CHECK(cond)                                                 \
  do {                                                                              \
    if (!(cond)) {                                                                  \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                 \
    }                                                                               \
  } while (0)

// A level pixel as one sortable number (levels are far narrower than 2^31 px).
int64_t RasterIndex(const cv::Point& p) { return (static_cast<int64_t>(p.y) << 32) + p.x; }

constexpr int kFastRing = 3;                               // FAST's circle radius
constexpr int kDetectBorder = kEdgeThreshold - kFastRing;  // FAST window starts 16 px inside

std::vector<int> FeaturesPerLevel(const OrbOptions& o) {
  std::vector<int> budget(o.n_levels, 0);
  const double f = 1.0 / o.scale_factor;
  double per_scale = o.n_features * (1.0 - f) / (1.0 - std::pow(f, o.n_levels));
  int64_t sum = 0;
  for (int l = 0; l + 1 < o.n_levels; ++l) {
    budget[l] = static_cast<int>(std::lround(per_scale));
    sum += budget[l];
    per_scale *= f;
  }
  budget[o.n_levels - 1] = static_cast<int>(std::max<int64_t>(o.n_features - sum, 0));
  return budget;
}

}  // namespace

void OrbOptions::Validate() const {
  auto fail = [](const std::string& what) { throw InputError("OrbOptions: " + what); };
  if (n_features < 1 || n_features > kMaxOrbFeatures) {
    fail("n_features must be in [1, " + std::to_string(kMaxOrbFeatures) + "], got " +
         std::to_string(n_features));
  }
  if (!(scale_factor >= kMinOrbScaleFactor && scale_factor <= 4.0)) {
    fail("scale_factor must be in [1.05, 4], got " + std::to_string(scale_factor));
  }
  if (n_levels < 1 || n_levels > 32)
    fail("n_levels must be in [1, 32], got " + std::to_string(n_levels));
  if (ini_th_fast < 1 || ini_th_fast > 254) {
    fail("ini_th_fast must be in [1, 254], got " + std::to_string(ini_th_fast));
  }
  if (min_th_fast < 1 || min_th_fast > ini_th_fast) {
    fail("min_th_fast must be in [1, ini_th_fast], got " + std::to_string(min_th_fast));
  }
  if (cell_size_px < 8) fail("cell_size_px must be >= 8, got " + std::to_string(cell_size_px));
}

OrbExtractor::OrbExtractor(const OrbOptions& options) : options_(options) {
  options_.Validate();
  levels_ = ScaleLevels(options_.n_levels, options_.scale_factor);
  features_per_level_ = FeaturesPerLevel(options_);
}

std::vector<cv::KeyPoint> OrbExtractor::FastCornersOnLevel(const cv::Mat& level, int budget) const {
  // FAST runs on the window [16, size − 16); its 3-px ring keeps corners ≥ 19 px inside.
  const int w = level.cols - 2 * kDetectBorder, h = level.rows - 2 * kDetectBorder;
  const int inner_w = w - 2 * kFastRing, inner_h = h - 2 * kFastRing;
  if (budget <= 0 || inner_w <= 0 || inner_h <= 0) return {};
  const cv::Mat window = level(cv::Rect(kDetectBorder, kDetectBorder, w, h));

  // One FAST pass at the initial threshold over the whole window. With non-maximum suppression
  // this equals ORB-SLAM's per-cell FAST(ini_th_fast) except across cell boundaries, where the
  // whole-window pass suppresses duplicate corners that per-cell passes would both keep.
  std::vector<cv::KeyPoint> found;
  cv::FAST(window, found, options_.ini_th_fast, true);

  // Cells tile the region where FAST can fire, [3, w − 3) × [3, h − 3) in window coordinates.
  const int n_cols =
      std::max(1, static_cast<int>(std::lround(double(inner_w) / options_.cell_size_px)));
  const int n_rows =
      std::max(1, static_cast<int>(std::lround(double(inner_h) / options_.cell_size_px)));
  const int cell_w = (inner_w + n_cols - 1) / n_cols, cell_h = (inner_h + n_rows - 1) / n_rows;
  std::vector<uint8_t> occupied(n_cols * n_rows, 0);
  for (const cv::KeyPoint& kp : found) {
    const int c = std::min((static_cast<int>(kp.pt.x) - kFastRing) / cell_w, n_cols - 1);
    const int r = std::min((static_cast<int>(kp.pt.y) - kFastRing) / cell_h, n_rows - 1);
    occupied[r * n_cols + c] = 1;
  }
  // Fallback: FAST at the lower threshold in each empty cell (its window grown by the ring).
  std::vector<cv::KeyPoint> cell_found;
  for (int r = 0; r < n_rows; ++r) {
    for (int c = 0; c < n_cols; ++c) {
      if (occupied[r * n_cols + c]) continue;
      const int x0 = c * cell_w, y0 = r * cell_h;  // cell [x0 + 3, ...) grown by 3 → [x0, ...)
      const int x1 = std::min(x0 + cell_w + 2 * kFastRing, w);
      const int y1 = std::min(y0 + cell_h + 2 * kFastRing, h);
      if (x1 - x0 <= 2 * kFastRing || y1 - y0 <= 2 * kFastRing) continue;
      cell_found.clear();
      cv::FAST(window(cv::Rect(x0, y0, x1 - x0, y1 - y0)), cell_found, options_.min_th_fast, true);
      for (cv::KeyPoint& kp : cell_found) {
        kp.pt.x += x0;
        kp.pt.y += y0;
        found.push_back(kp);
      }
    }
  }
  for (cv::KeyPoint& kp : found) {
    kp.pt.x += kDetectBorder;
    kp.pt.y += kDetectBorder;
  }
  return found;
}

std::vector<cv::KeyPoint> OrbExtractor::DistributeOnLevel(const cv::Mat& level,
                                                          std::vector<cv::KeyPoint> found,
                                                          int budget) const {
  const int w = level.cols - 2 * kDetectBorder, h = level.rows - 2 * kDetectBorder;
  if (budget <= 0 || found.empty()) return {};
  const cv::Rect2f region(kDetectBorder, kDetectBorder, w, h);
  const std::vector<int> kept = DistributeQuadtree(found, region, budget);
  std::vector<cv::KeyPoint> out;
  out.reserve(kept.size());
  for (int i : kept) out.push_back(found[i]);
  return out;
}

KeypointSet OrbExtractor::Detect(const cv::Mat& image) const {
  if (image.empty()) throw InputError("OrbExtractor::Detect: empty image");
  if (image.type() != CV_8UC1) {
    throw InputError("OrbExtractor::Detect: expected an 8-bit single-channel image, got type " +
                     std::to_string(image.type()));
  }
  return DetectOnPyramid(std::make_shared<ImagePyramid>(image, levels_), cv::Mat(), nullptr,
                         nullptr);
}

KeypointSet OrbExtractor::DetectExcluding(const KeypointSet& base, const cv::Mat& exclude) const {
  if (base.pyramid == nullptr)
    throw InputError("OrbExtractor::DetectExcluding: the base set has no pyramid");
  if (base.pyramid->NumLevels() != levels_.NumLevels()) {
    throw InputError("OrbExtractor::DetectExcluding: the base set's pyramid has " +
                     std::to_string(base.pyramid->NumLevels()) + " levels, this extractor " +
                     std::to_string(levels_.NumLevels()));
  }
  const cv::Size full = base.pyramid->Level(0).size();
  if (exclude.type() != CV_8UC1 || exclude.size() != full) {
    throw InputError("OrbExtractor::DetectExcluding: the mask must be CV_8UC1 of the image size");
  }
  return DetectOnPyramid(base.pyramid, exclude, base.candidates, &base);
}

KeypointSet OrbExtractor::DetectOnPyramid(
    std::shared_ptr<const ImagePyramid> pyramid, const cv::Mat& exclude,
    std::shared_ptr<const std::vector<std::vector<cv::KeyPoint>>> candidates,
    const KeypointSet* oriented) const {
  KeypointSet set;
  // Levels are independent: detect them on OpenCV's worker threads, then concatenate in level
  // order, so the result is the same whatever the thread count.
  const int num_levels = pyramid->NumLevels();
  std::vector<std::vector<cv::KeyPoint>> per_level(num_levels);
  std::vector<std::vector<cv::Point>> pixels(num_levels);
  // FAST corners: reused from an earlier detection on the same pyramid (shared, not copied), or
  // found now.
  const bool have_corners = candidates != nullptr && static_cast<int>(candidates->size()) == num_levels;
  std::shared_ptr<std::vector<std::vector<cv::KeyPoint>>> fresh;
  if (!have_corners) fresh = std::make_shared<std::vector<std::vector<cv::KeyPoint>>>(num_levels);
  // Angles already computed on this pyramid, per level, sorted by the level pixel's raster index.
  std::vector<std::vector<std::pair<int64_t, float>>> known(num_levels);
  if (oriented != nullptr && oriented->pyramid == pyramid &&
      oriented->level_pixels.size() == oriented->keypoints.size()) {
    for (size_t i = 0; i < oriented->keypoints.size(); ++i) {
      const int l = oriented->keypoints[i].octave;
      if (l < 0 || l >= num_levels) continue;
      const cv::Point& p = oriented->level_pixels[i];
      known[l].emplace_back(RasterIndex(p), oriented->keypoints[i].angle);
    }
    for (auto& level_known : known) std::sort(level_known.begin(), level_known.end());
  }
  cv::parallel_for_(cv::Range(0, num_levels), [&](const cv::Range& range) {
    for (int l = range.start; l < range.end; ++l) {
      if (!pyramid->LevelUsable(l)) continue;
      const cv::Mat& level = pyramid->Level(l);
      if (!have_corners) (*fresh)[l] = FastCornersOnLevel(level, features_per_level_[l]);
      const std::vector<cv::KeyPoint>& level_corners = have_corners ? (*candidates)[l] : (*fresh)[l];
      std::vector<cv::KeyPoint> allowed;
      if (exclude.empty()) {
        allowed = level_corners;
      } else {
        // Look each corner up at its full-resolution position (no per-level mask resampling,
        // which cost more than the whole detection).
        allowed.reserve(level_corners.size());
        std::copy_if(level_corners.begin(), level_corners.end(), std::back_inserter(allowed),
                     [&](const cv::KeyPoint& kp) {
                       const cv::Point2f f = pyramid->LevelToFull(l, kp.pt);
                       const int x = std::clamp(static_cast<int>(f.x + 0.5f), 0, exclude.cols - 1);
                       const int y = std::clamp(static_cast<int>(f.y + 0.5f), 0, exclude.rows - 1);
                       return exclude.at<uint8_t>(y, x) == 0;
                     });
      }
      per_level[l] = DistributeOnLevel(level, std::move(allowed), features_per_level_[l]);
      const float size = static_cast<float>(kPatchSize * levels_.scale[l]);
      for (cv::KeyPoint& kp : per_level[l]) {
        const cv::Point pixel(static_cast<int>(kp.pt.x), static_cast<int>(kp.pt.y));
        const std::vector<std::pair<int64_t, float>>& level_known = known[l];
        const int64_t index = RasterIndex(pixel);
        const auto hit = std::lower_bound(
            level_known.begin(), level_known.end(), index,
            [](const std::pair<int64_t, float>& e, int64_t v) { return e.first < v; });
        kp.angle = hit != level_known.end() && hit->first == index
                       ? hit->second
                       : IntensityCentroidAngleDeg(level, pixel);
        kp.pt = pyramid->LevelToFull(l, kp.pt);
        kp.octave = l;
        kp.size = size;
        kp.class_id = -1;
        pixels[l].push_back(pixel);
      }
    }
  });
  for (int l = 0; l < num_levels; ++l) {
    set.keypoints.insert(set.keypoints.end(), per_level[l].begin(), per_level[l].end());
    set.level_pixels.insert(set.level_pixels.end(), pixels[l].begin(), pixels[l].end());
  }
  set.pyramid = std::move(pyramid);
  if (have_corners) {
    set.candidates = std::move(candidates);
  } else {
    set.candidates = std::move(fresh);
  }
  return set;
}

cv::Mat OrbExtractor::Describe(const KeypointSet& set, const std::vector<int>& indices) const {
  cv::Mat descriptors(static_cast<int>(indices.size()), kBriefBytes, CV_8UC1);
  if (indices.empty()) return descriptors;
  DYNORB_FEATURES_CHECK(set.pyramid != nullptr);
  DYNORB_FEATURES_CHECK(set.level_pixels.size() == set.keypoints.size());
  const ImagePyramid& pyramid = *set.pyramid;
  std::vector<bool> level_used(pyramid.NumLevels(), false);
  for (const int k : indices) {
    DYNORB_FEATURES_CHECK(k >= 0 && k < set.size());
    const int l = set.keypoints[k].octave;
    DYNORB_FEATURES_CHECK(l >= 0 && l < pyramid.NumLevels() && pyramid.LevelUsable(l));
    level_used[l] = true;
  }
  // Blur the used levels, then describe; both in parallel, each output written by one worker.
  std::vector<cv::Mat> blurred(pyramid.NumLevels());
  cv::parallel_for_(cv::Range(0, pyramid.NumLevels()), [&](const cv::Range& range) {
    for (int l = range.start; l < range.end; ++l) {
      if (level_used[l]) {
        cv::GaussianBlur(pyramid.Level(l), blurred[l], cv::Size(7, 7), 2.0, 2.0,
                         cv::BORDER_REFLECT_101);
      }
    }
  });
  cv::parallel_for_(cv::Range(0, static_cast<int>(indices.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const int k = indices[i];
      ComputeSteeredBrief(blurred[set.keypoints[k].octave], set.level_pixels[k],
                          set.keypoints[k].angle, descriptors.ptr<uint8_t>(i));
    }
  });
  return descriptors;
}

cv::Mat OrbExtractor::Describe(const KeypointSet& set) const {
  std::vector<int> all(set.size());
  for (int i = 0; i < set.size(); ++i) all[i] = i;
  return Describe(set, all);
}

OrbFeatures OrbExtractor::DescribeKept(const KeypointSet& set,
                                       const std::vector<bool>& keep) const {
  DYNORB_FEATURES_CHECK(static_cast<int>(keep.size()) == set.size());
  std::vector<int> indices;
  OrbFeatures out;
  for (int i = 0; i < set.size(); ++i) {
    if (!keep[i]) continue;
    indices.push_back(i);
    out.keypoints.push_back(set.keypoints[i]);
  }
  out.descriptors = Describe(set, indices);
  return out;
}

OrbFeatures OrbExtractor::DetectAndDescribe(const cv::Mat& image) const {
  KeypointSet set = Detect(image);
  OrbFeatures out;
  out.descriptors = Describe(set);
  out.keypoints = std::move(set.keypoints);
  return out;
}

}  // namespace dynorb
