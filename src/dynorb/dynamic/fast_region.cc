#include "dynorb/dynamic/fast_region.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "dynorb/dynamic/fast_cues.h"
#include "dynorb/dynamic/morphology.h"

namespace dynorb {
namespace {

cv::Point LowPixel(const cv::Point2f& p, int scale, cv::Size size) {
  return {std::clamp(static_cast<int>(std::lround((p.x + 0.5f) / scale - 0.5f)), 0, size.width - 1),
          std::clamp(static_cast<int>(std::lround((p.y + 0.5f) / scale - 0.5f)), 0, size.height - 1)};
}

}  // namespace

cv::Mat DownsampleDepth(const cv::Mat& depth_m, int scale, float max_depth_m) {
  const int s = scale;
  cv::Mat low((depth_m.rows + s - 1) / s, (depth_m.cols + s - 1) / s, CV_32F);
  for (int y = 0; y < low.rows; ++y) {
    const float* row = depth_m.ptr<float>(std::min(depth_m.rows - 1, y * s + s / 2));
    float* out = low.ptr<float>(y);
    for (int x = 0; x < low.cols; ++x) {
      const float z = row[std::min(depth_m.cols - 1, x * s + s / 2)];
      out[x] = (z > 0.f && z <= max_depth_m) ? z : 0.f;
    }
  }
  return low;
}

bool MaskWithinRadius(const cv::Mat& mask, cv::Point2f pixel, float radius_px) {
  const int cx = static_cast<int>(std::lround(pixel.x)),
            cy = static_cast<int>(std::lround(pixel.y));
  const int r = static_cast<int>(std::floor(radius_px));
  const float r2 = radius_px * radius_px;
  for (int y = std::max(0, cy - r); y <= std::min(mask.rows - 1, cy + r); ++y) {
    const uint8_t* row = mask.ptr<uint8_t>(y);
    const float dy2 = static_cast<float>((y - cy) * (y - cy));
    for (int x = std::max(0, cx - r); x <= std::min(mask.cols - 1, cx + r); ++x) {
      if (row[x] && static_cast<float>((x - cx) * (x - cx)) + dy2 <= r2) return true;
    }
  }
  return false;
}

cv::Mat UpsampleAndDilate(const cv::Mat& low_mask, int scale, cv::Size full_size, int dilate_px) {
  cv::Mat full = cv::Mat::zeros(full_size, CV_8U);
  const cv::Rect box = cv::boundingRect(low_mask);
  if (box.empty()) return full;
  // The set blocks, cropped to the image.
  const cv::Rect image(0, 0, full_size.width, full_size.height);
  const cv::Rect blocks = cv::Rect(box.x * scale, box.y * scale, box.width * scale, box.height * scale) & image;
  if (blocks.empty()) return full;
  cv::Mat up;
  cv::resize(low_mask(box), up, cv::Size(box.width * scale, box.height * scale), 0, 0, cv::INTER_NEAREST);
  up(cv::Rect(0, 0, blocks.width, blocks.height)).copyTo(full(blocks));
  if (dilate_px > 0) {
    // Outside this window every pixel is farther than the radius from a set one, so stays 0.
    const cv::Rect window = cv::Rect(blocks.x - dilate_px, blocks.y - dilate_px,
                                     blocks.width + 2 * dilate_px, blocks.height + 2 * dilate_px) &
                            image;
    cv::Mat dilated;
    DilateEllipse(full(window), dilate_px, &dilated);
    dilated.copyTo(full(window));
  }
  return full;
}

RegionResult GrowRegions(const cv::Mat& low, cv::Size full_size, const std::vector<RegionPoint>& seeds,
                         const std::vector<RegionPoint>& statics, const cv::Mat& suspect_low,
                         const RegionOptions& options) {
  RegionResult result;
  const int s = options.scale;
  const cv::Size low_size = low.size();
  const int width = low_size.width, height = low_size.height;
  // Flat row-major views: the flood fill below visits every pixel of large regions.
  const cv::Mat depth = low.isContinuous() ? low : low.clone();
  const float* z = depth.ptr<float>();
  std::vector<int> labels(static_cast<size_t>(low_size.area()), -1);
  struct Region {
    int seeds = 0, statics = 0, area = 0;
    bool suspect = false;
    cv::Point2f motion_sum{0.f, 0.f};
    float motion_norm_sum = 0.f;
  };
  std::vector<Region> regions;
  std::vector<int> queue;
  for (const RegionPoint& seed : seeds) {
    if (seed.depth_m <= 0.f) continue;
    const cv::Point c = LowPixel(seed.pixel, s, low_size);
    // Start at the 3×3 low-resolution pixel whose depth is closest to the seed's.
    int start = -1;
    float best = static_cast<float>(options.band_m);
    for (int y = std::max(0, c.y - 1); y <= std::min(height - 1, c.y + 1); ++y) {
      for (int x = std::max(0, c.x - 1); x <= std::min(width - 1, c.x + 1); ++x) {
        const float zs = z[y * width + x];
        if (zs > 0.f && std::abs(zs - seed.depth_m) < best)
          best = std::abs(zs - seed.depth_m), start = y * width + x;
      }
    }
    if (start < 0) continue;
    const int existing = labels[start];
    const float motion_norm = std::hypot(seed.motion.x, seed.motion.y);
    if (existing >= 0) {
      ++regions[existing].seeds;
      regions[existing].motion_sum += seed.motion;
      regions[existing].motion_norm_sum += motion_norm;
      continue;
    }
    const int label = static_cast<int>(regions.size());
    regions.push_back({1, 0, 0, false, seed.motion, motion_norm});
    const float z_ref = z[start];
    queue.clear();
    queue.push_back(start);
    labels[start] = label;
    // Breadth first, neighbours right, left, down, up.
    auto visit = [&](int n, float zp, float step) {
      if (labels[n] >= 0) return;
      const float zn = z[n];
      if (zn <= 0.f || std::abs(zn - zp) > step || std::abs(zn - z_ref) > options.band_m) return;
      labels[n] = label;
      queue.push_back(n);
    };
    for (size_t q = 0; q < queue.size(); ++q) {
      const int p = queue[q];
      const int x = p % width, y = p / width;
      const float zp = z[p];
      const float step = static_cast<float>(options.edge_abs_m + options.edge_rel * zp);
      if (x + 1 < width) visit(p + 1, zp, step);
      if (x > 0) visit(p - 1, zp, step);
      if (y + 1 < height) visit(p + width, zp, step);
      if (y > 0) visit(p - width, zp, step);
    }
    regions[label].area = static_cast<int>(queue.size());
  }
  result.num_regions = static_cast<int>(regions.size());
  for (const RegionPoint& p : statics) {
    const cv::Point lp = LowPixel(p.pixel, s, low_size);
    const int label = labels[lp.y * width + lp.x];
    if (label >= 0) ++regions[label].statics;
  }
  if (!suspect_low.empty()) {
    for (int y = 0; y < height; ++y) {
      const uint8_t* row = suspect_low.ptr<uint8_t>(y);
      const int* label_row = labels.data() + y * width;
      for (int x = 0; x < width; ++x) {
        if (label_row[x] >= 0 && row[x]) regions[label_row[x]].suspect = true;
      }
    }
  }
  std::vector<uint8_t> accepted(regions.size(), 0);
  const double total = static_cast<double>(low_size.area());
  for (size_t i = 0; i < regions.size(); ++i) {
    const Region& r = regions[i];
    const int need = r.suspect ? 1 : options.min_seeds;
    const double static_ratio = static_cast<double>(r.statics) / (r.statics + r.seeds);
    const double coherence =
        r.motion_norm_sum > 0.f ? std::hypot(r.motion_sum.x, r.motion_sum.y) / r.motion_norm_sum : 1.0;
    const bool coherent = coherence >= options.min_coherence || r.seeds >= options.coherent_free_seeds || r.suspect;
    if (r.seeds >= need && coherent && static_ratio <= options.max_static_ratio &&
        r.area <= options.max_area * total) {
      accepted[i] = 1;
      ++result.num_accepted;
    }
  }
  result.low_mask = cv::Mat::zeros(low_size, CV_8U);
  if (result.num_accepted > 0) {
    for (int y = 0; y < height; ++y) {
      uint8_t* row = result.low_mask.ptr<uint8_t>(y);
      const int* label_row = labels.data() + y * width;
      for (int x = 0; x < width; ++x) {
        if (label_row[x] >= 0 && accepted[label_row[x]]) row[x] = 255;
      }
    }
  }
  result.mask = UpsampleAndDilate(result.low_mask, s, full_size, result.num_accepted > 0 ? options.dilate_px : 0);
  return result;
}

cv::Mat SuspectMap::Suspect(int max_age) const {
  cv::Mat out;
  if (age.empty()) return out;
  cv::compare(age, cv::Scalar(max_age), out, cv::CMP_LE);
  return out;
}

SuspectMap PropagateSuspect(const SuspectMap& previous, const cv::Mat& low_depth_cur, const PinholeCamera& camera,
                            int scale, const Rigid3d& prev_from_cur, int max_age, double depth_tol_m) {
  SuspectMap out;
  out.age = cv::Mat(low_depth_cur.size(), CV_8U, cv::Scalar(255));
  out.depth = cv::Mat::zeros(low_depth_cur.size(), CV_32F);
  if (previous.empty() || previous.age.size() != low_depth_cur.size() ||
      previous.depth.size() != previous.age.size() || previous.depth.type() != CV_32F) {
    return out;
  }
  // Nothing young enough to carry over: nothing to warp.
  double youngest = 0.0;
  cv::minMaxLoc(previous.age, &youngest);
  if (youngest >= max_age) return out;
  // The point of pixel (u, v) with depth z lands at z * (m * (u, v, 1)) + t in the previous camera,
  // m = R * K^-1: one column step per pixel instead of a back-projection and a rotation.
  const Eigen::Matrix3d k_inv = (Eigen::Matrix3d() << 1.0 / camera.fx, 0.0, -camera.cx / camera.fx,
                                 0.0, 1.0 / camera.fy, -camera.cy / camera.fy, 0.0, 0.0, 1.0)
                                    .finished();
  const Eigen::Matrix3d m = prev_from_cur.rotation.toRotationMatrix() * k_inv;
  const Eigen::Vector3d& t = prev_from_cur.translation;
  for (int y = 0; y < low_depth_cur.rows; ++y) {
    const float* depth_row = low_depth_cur.ptr<float>(y);
    uint8_t* age_row = out.age.ptr<uint8_t>(y);
    float* out_depth_row = out.depth.ptr<float>(y);
    const Eigen::Vector3d row_ray = m * Eigen::Vector3d(0.0, y * scale + scale / 2, 1.0);
    for (int x = 0; x < low_depth_cur.cols; ++x) {
      const float z = depth_row[x];
      if (z <= 0.f) continue;
      const Eigen::Vector3d p =
          z * (row_ray + m.col(0) * static_cast<double>(x * scale + scale / 2)) + t;
      if (p.z() <= 1e-6) continue;
      const double u = camera.fx * p.x() / p.z() + camera.cx,
                   v = camera.fy * p.y() / p.z() + camera.cy;
      // Nearest low-resolution pixel of the previous map; outside it: nothing carried over.
      const double lx = (u + 0.5) / scale - 0.5, ly = (v + 0.5) / scale - 0.5;
      if (!(lx > -0.5 && ly > -0.5 && lx < low_depth_cur.cols - 0.5 &&
            ly < low_depth_cur.rows - 0.5)) {
        continue;
      }
      const int px = static_cast<int>(lx + 0.5), py = static_cast<int>(ly + 0.5);
      const int age = previous.age.at<uint8_t>(py, px);
      if (age >= max_age) continue;
      if (std::abs(previous.depth.at<float>(py, px) - p.z()) > depth_tol_m) continue;
      age_row[x] = static_cast<uint8_t>(age + 1);
      out_depth_row[x] = z;
    }
  }
  return out;
}

void AddToSuspect(const cv::Mat& low_mask, const cv::Mat& low_depth, SuspectMap* map) {
  if (map->age.empty()) {
    map->age = cv::Mat(low_mask.size(), CV_8U, cv::Scalar(255));
    map->depth = cv::Mat::zeros(low_mask.size(), CV_32F);
  }
  for (int y = 0; y < low_mask.rows; ++y) {
    for (int x = 0; x < low_mask.cols; ++x) {
      if (!low_mask.at<uint8_t>(y, x) || low_depth.at<float>(y, x) <= 0.f) continue;
      map->age.at<uint8_t>(y, x) = 0;
      map->depth.at<float>(y, x) = low_depth.at<float>(y, x);
    }
  }
}

}  // namespace dynorb
