#include "dynorb/synth/sensor_noise.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace dynorb::synth {
namespace {

constexpr double kFocalBaseline = 580.0 * 0.075;  // Kinect v1 IR focal length (px) * baseline (m)

// Fast standard-normal samples: a fixed table of 65536 normal variates (drawn once from a
// constant seed) indexed by a seeded xorshift64* generator; ~10x faster than cv::RNG's normals.
class FastNormal {
 public:
  explicit FastNormal(uint64_t seed)
      : state_(seed * 0x9E3779B97F4A7C15ULL + 0x2545F4914F6CDD1DULL) {
    if (state_ == 0) state_ = 1;
  }
  float operator()() {
    state_ ^= state_ >> 12;
    state_ ^= state_ << 25;
    state_ ^= state_ >> 27;
    return Table()[(state_ * 0x2545F4914F6CDD1DULL) >> 48];
  }

 private:
  static const float* Table() {
    static const std::vector<float> table = [] {
      cv::Mat values(1, 65536, CV_32F);
      cv::RNG(20240601).fill(values, cv::RNG::NORMAL, 0.0, 1.0);
      return std::vector<float>(values.begin<float>(), values.end<float>());
    }();
    return table.data();
  }
  uint64_t state_;
};

}  // namespace

cv::Mat DepthToSensor(const cv::Mat& depth_m, const SensorOptions& options, uint64_t seed) {
  CV_Assert(depth_m.type() == CV_32F);
  const int w = depth_m.cols, h = depth_m.rows;
  cv::Mat out(depth_m.size(), CV_16U);
  if (!options.noise) {
    for (int y = 0; y < h; ++y) {
      const float* d = depth_m.ptr<float>(y);
      uint16_t* o = out.ptr<uint16_t>(y);
      for (int x = 0; x < w; ++x) {
        const double z = d[x];
        o[x] = (z > 0.0 && z <= options.max_depth_m)
                   ? static_cast<uint16_t>(std::lround(z * options.depth_factor))
                   : 0;
      }
    }
    return out;
  }
  cv::RNG rng(seed);
  // Correlated noise (block matching window) plus a little per-pixel noise, in units of sigma.
  cv::Mat coarse(h / 4 + 1, w / 4 + 1, CV_32F), correlated, fine(depth_m.size(), CV_32F);
  rng.fill(coarse, cv::RNG::NORMAL, 0.0, 1.0);
  cv::resize(coarse, correlated, depth_m.size(), 0, 0, cv::INTER_LINEAR);
  FastNormal normal(seed);
  for (int y = 0; y < h; ++y) {
    float* row = fine.ptr<float>(y);
    for (int x = 0; x < w; ++x) row[x] = 0.5f * normal();
  }
  // Invalid pixels: depth discontinuities and the projector's shadow left of foreground edges.
  cv::Mat edges = cv::Mat::zeros(depth_m.size(), CV_8U);
  cv::Mat invalid = cv::Mat::zeros(depth_m.size(), CV_8U);
  for (int y = 0; y < h; ++y) {
    const float* d = depth_m.ptr<float>(y);
    const float* up = depth_m.ptr<float>(std::max(0, y - 1));
    uchar* e = edges.ptr<uchar>(y);
    uchar* inv = invalid.ptr<uchar>(y);
    for (int x = 1; x < w; ++x) {
      const float a = d[x - 1], b = d[x];
      const float near = std::min(a, b);
      const float limit = 0.04f * near * near + 0.03f;
      if (std::abs(a - b) > limit || std::abs(up[x] - b) > limit) e[x] = 1;
      if (b > 0.0f && a > b + 0.1f) {
        const double far = a > 0.0f ? a : 10.0;
        const int width =
            static_cast<int>(0.5 * kFocalBaseline * (1.0 / b - 1.0 / far) + rng.uniform(0.0, 1.0));
        for (int k = 1; k <= width && x - k >= 0; ++k) inv[x - k] = 1;
      }
    }
  }
  // Ragged holes along the edges: the hole radius (0.5-3 px) follows a smooth random field.
  cv::Mat distance;
  cv::distanceTransform(edges == 0, distance, cv::DIST_L2, 3);
  // The right border has no registered depth (as in TUM's Kinect frames).
  const int right_band = 6 + static_cast<int>(rng.uniform(0, 4));
  for (int y = 0; y < h; ++y) {
    const float* dist = distance.ptr<float>(y);
    const float* c = correlated.ptr<float>(y);
    uchar* inv = invalid.ptr<uchar>(y);
    for (int x = 0; x < w; ++x) {
      if (dist[x] < 0.8f + 1.2f * std::max(0.0f, c[x] + 0.5f)) inv[x] = 1;
      if (x >= w - right_band) inv[x] = 1;
    }
  }
  const double q = 1.0 / 8.0;  // disparity quantisation
  for (int y = 0; y < h; ++y) {
    const float* d = depth_m.ptr<float>(y);
    const float* c = correlated.ptr<float>(y);
    const float* f = fine.ptr<float>(y);
    const uchar* inv = invalid.ptr<uchar>(y);
    uint16_t* o = out.ptr<uint16_t>(y);
    for (int x = 0; x < w; ++x) {
      const double z = d[x];
      o[x] = 0;
      if (z <= 0.0 || inv[x]) continue;
      // Range limit with a ragged edge (the smooth field again); rare speckle dropouts.
      if (z > options.max_depth_m - 0.25 * std::max(0.0f, c[x])) continue;
      if (f[x] > 1.45f) continue;  // ~0.2 % of the pixels
      const double sigma = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
      const double noisy = z + sigma * (c[x] + f[x]);
      const double steps =
          static_cast<double>(static_cast<int64_t>(kFocalBaseline / (noisy * q) + 0.5));
      const double zq = kFocalBaseline / (steps * q);  // steps >= 77 for z <= 4.5 m
      o[x] = static_cast<uint16_t>(std::min(65535.0, zq * options.depth_factor + 0.5));
    }
  }
  return out;
}

void ApplyRgbEffects(cv::Mat* rgb, const cv::Point2d& motion_px, double gain,
                     const SensorOptions& options, uint64_t seed) {
  if (!options.noise) return;
  cv::Mat& img = *rgb;
  // The Kinect's RGB optics and demosaicing are soft.
  cv::GaussianBlur(img, img, cv::Size(3, 3), 0.5);
  // Motion blur: a line kernel along the image motion.
  const double length = options.exposure_fraction * std::hypot(motion_px.x, motion_px.y);
  if (length > 0.7) {
    const int size = 2 * static_cast<int>(std::ceil(length / 2.0)) + 1;
    cv::Mat kernel = cv::Mat::zeros(size, size, CV_32F);
    const cv::Point2d dir = motion_px * (1.0 / std::hypot(motion_px.x, motion_px.y));
    const int samples = 4 * size;
    for (int i = 0; i < samples; ++i) {
      const double s = (i / (samples - 1.0) - 0.5) * length;
      const double px = size / 2 + s * dir.x, py = size / 2 + s * dir.y;
      const int x0 = static_cast<int>(std::floor(px)), y0 = static_cast<int>(std::floor(py));
      const float fx = static_cast<float>(px - x0), fy = static_cast<float>(py - y0);
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const int xx = std::clamp(x0 + dx, 0, size - 1), yy = std::clamp(y0 + dy, 0, size - 1);
          kernel.at<float>(yy, xx) += (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy);
        }
    }
    kernel /= cv::sum(kernel)[0];
    cv::filter2D(img, img, -1, kernel, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
  }
  // Gain with vignetting, shot + read noise (sigma^2 = 2.0^2 + 0.12 * I), in 8-bit.
  const int w = img.cols, h = img.rows;
  const double cx = 0.5 * (w - 1), cy = 0.5 * (h - 1), r2max = cx * cx + cy * cy;
  float sigma_of[256];
  for (int i = 0; i < 256; ++i) sigma_of[i] = static_cast<float>(std::sqrt(4.0 + 0.12 * i));
  std::vector<float> column_term(w);
  for (int x = 0; x < w; ++x) column_term[x] = static_cast<float>((x - cx) * (x - cx) / r2max);
  FastNormal normal(seed);
  for (int y = 0; y < h; ++y) {
    uchar* p = img.ptr<uchar>(y);
    const float row_term = static_cast<float>((y - cy) * (y - cy) / r2max);
    const float g0 = static_cast<float>(gain);
    for (int x = 0; x < w; ++x) {
      const float g = g0 * (1.0f - 0.22f * (column_term[x] + row_term));
      for (int c = 0; c < 3; ++c) {
        const float v = p[3 * x + c] * g;
        const int iv = std::min(static_cast<int>(v), 255);
        const float noisy = v + sigma_of[iv] * normal() + 0.5f;
        p[3 * x + c] = static_cast<uchar>(std::clamp(noisy, 0.0f, 255.0f));
      }
    }
  }
}

}  // namespace dynorb::synth
