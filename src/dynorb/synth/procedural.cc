#include "dynorb/synth/procedural.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace dynorb::synth {
namespace {

cv::Scalar Jitter(cv::Scalar bgr, double amount, cv::RNG& rng) {
  const double common = rng.uniform(-amount, amount);
  for (int i = 0; i < 3; ++i)
    bgr[i] = std::clamp(bgr[i] * (1.0 + common) + rng.uniform(-8.0, 8.0), 0.0, 255.0);
  return bgr;
}

void AddGrain(cv::Mat& img, double sigma, cv::RNG& rng) {
  cv::Mat grain(img.size(), CV_16SC3);
  rng.fill(grain, cv::RNG::NORMAL, 0.0, sigma);
  cv::Mat tmp;
  img.convertTo(tmp, CV_16SC3);
  tmp += grain;
  tmp.convertTo(img, CV_8UC3);
}

}  // namespace

cv::Mat FractalNoise(cv::Size size, double cell_px, int octaves, cv::RNG& rng) {
  cv::Mat sum = cv::Mat::zeros(size, CV_32F);
  double amplitude = 1.0, total = 0.0;
  for (int o = 0; o < octaves; ++o) {
    const int gw = std::max(2, static_cast<int>(std::ceil(size.width / cell_px)) + 1);
    const int gh = std::max(2, static_cast<int>(std::ceil(size.height / cell_px)) + 1);
    cv::Mat grid(gh, gw, CV_32F);
    rng.fill(grid, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::Mat up;
    cv::resize(grid, up, size, 0, 0, cv::INTER_CUBIC);
    sum += amplitude * up;
    total += amplitude;
    amplitude *= 0.5;
    cell_px = std::max(1.0, cell_px * 0.5);
  }
  sum /= total;
  return sum;
}

cv::Mat NoisyColor(cv::Size size, cv::Scalar bgr, double amplitude, double cell_px, cv::RNG& rng) {
  cv::Mat noise = FractalNoise(size, cell_px, 5, rng);
  cv::Mat img(size, CV_8UC3);
  for (int y = 0; y < size.height; ++y) {
    const float* n = noise.ptr<float>(y);
    auto* p = img.ptr<cv::Vec3b>(y);
    for (int x = 0; x < size.width; ++x) {
      const double f = 1.0 + amplitude * (2.0 * n[x] - 1.0);
      for (int c = 0; c < 3; ++c) p[x][c] = cv::saturate_cast<uchar>(bgr[c] * f);
    }
  }
  AddGrain(img, 2.0, rng);
  return img;
}

cv::Mat Carpet(cv::Size size, cv::Scalar bgr, cv::RNG& rng) {
  cv::Mat img = NoisyColor(size, bgr, 0.18, 48.0, rng);
  AddGrain(img, 9.0, rng);  // the fine fibre structure of office carpet tiles
  cv::GaussianBlur(img, img, cv::Size(3, 3), 0.7);
  // Carpet tile seams every ~0.5 m (texture assumed at ~200 px/m) and a few stains.
  for (int x = 100; x < size.width; x += 100) cv::line(img, {x, 0}, {x, size.height}, bgr * 0.8, 1);
  for (int y = 100; y < size.height; y += 100) cv::line(img, {0, y}, {size.width, y}, bgr * 0.8, 1);
  for (int i = 0; i < size.area() / 40000; ++i) {
    cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    cv::ellipse(img, c, cv::Size(rng.uniform(3, 14), rng.uniform(3, 10)), rng.uniform(0, 180), 0,
                360, bgr * rng.uniform(0.7, 0.9), cv::FILLED, cv::LINE_AA);
  }
  return img;
}

cv::Mat Wood(cv::Size size, cv::Scalar bgr, cv::RNG& rng) {
  cv::Mat noise = FractalNoise(size, 64.0, 4, rng);
  cv::Mat img(size, CV_8UC3);
  const double freq = rng.uniform(0.05, 0.09);
  for (int y = 0; y < size.height; ++y) {
    const float* n = noise.ptr<float>(y);
    auto* p = img.ptr<cv::Vec3b>(y);
    for (int x = 0; x < size.width; ++x) {
      const double ring = 0.5 + 0.5 * std::sin(freq * y + 9.0 * n[x]);
      const double f = 0.82 + 0.22 * ring * ring;
      for (int c = 0; c < 3; ++c) p[x][c] = cv::saturate_cast<uchar>(bgr[c] * f);
    }
  }
  AddGrain(img, 2.5, rng);
  return img;
}

cv::Mat Cardboard(cv::Size size, cv::RNG& rng) {
  cv::Mat img = NoisyColor(size, Jitter({95, 145, 185}, 0.08, rng), 0.12, 40.0, rng);
  AddGrain(img, 4.0, rng);
  // Packing tape and printed marks.
  const int tape = std::max(4, size.width / 8);
  cv::rectangle(img, {size.width / 2 - tape / 2, 0}, {size.width / 2 + tape / 2, size.height},
                {150, 175, 195}, cv::FILLED);
  for (int i = 0; i < 3; ++i) {
    cv::Point p(rng.uniform(0, std::max(1, size.width - 60)),
                rng.uniform(10, std::max(11, size.height)));
    cv::putText(img, i == 0 ? "FRAGILE" : (i == 1 ? "THIS SIDE UP" : "No. 4711"), p,
                cv::FONT_HERSHEY_SIMPLEX, std::max(0.3, size.width / 700.0), {40, 50, 60}, 2,
                cv::LINE_AA);
  }
  return img;
}

cv::Mat CeilingTiles(cv::Size size, double px_per_m, cv::RNG& rng) {
  cv::Mat img = NoisyColor(size, {205, 208, 210}, 0.05, 30.0, rng);
  AddGrain(img, 5.0, rng);
  const int tile = static_cast<int>(0.6 * px_per_m);
  for (int y = 0; y < size.height; y += tile) {
    for (int x = 0; x < size.width; x += tile) {
      if (rng.uniform(0.0, 1.0) < 0.18) {
        cv::rectangle(img, {x + 4, y + 4}, {x + tile - 4, y + tile - 4}, {250, 252, 252},
                      cv::FILLED);
        for (int k = x + 12; k < x + tile - 8; k += 12)
          cv::line(img, {k, y + 6}, {k, y + tile - 6}, {215, 220, 220}, 1);
      }
    }
  }
  for (int x = 0; x < size.width; x += tile)
    cv::line(img, {x, 0}, {x, size.height}, {150, 150, 150}, 2);
  for (int y = 0; y < size.height; y += tile)
    cv::line(img, {0, y}, {size.width, y}, {150, 150, 150}, 2);
  return img;
}

cv::Mat BookSpines(cv::Size size, cv::RNG& rng) {
  cv::Mat img(size, CV_8UC3, cv::Scalar(40, 45, 50));
  int x = 0;
  while (x < size.width) {
    const int w = rng.uniform(size.height / 14 + 2, size.height / 5 + 4);
    const int h = rng.uniform(size.height * 7 / 10, size.height);
    const cv::Scalar colour(rng.uniform(20, 230), rng.uniform(20, 230), rng.uniform(20, 230));
    cv::rectangle(img, {x, size.height - h}, {x + w - 1, size.height}, colour, cv::FILLED);
    cv::line(img, {x, size.height - h}, {x, size.height}, colour * 0.5, 1);
    for (int k = 0; k < 3; ++k) {
      const int y = size.height - h + rng.uniform(h / 8, std::max(h / 8 + 1, h - 8));
      cv::rectangle(img, {x + w / 4, y}, {x + 3 * w / 4, y + std::max(2, h / 30)},
                    rng.uniform(0, 2) ? cv::Scalar(235, 235, 235) : cv::Scalar(15, 15, 15),
                    cv::FILLED);
    }
    x += w;
  }
  AddGrain(img, 3.0, rng);
  return img;
}

cv::Mat Keyboard(cv::Size size, cv::RNG& rng) {
  cv::Mat img(size, CV_8UC3, cv::Scalar(48, 48, 52));
  const int rows = 6, cols = 18;
  const double kw = size.width / static_cast<double>(cols),
               kh = size.height / static_cast<double>(rows);
  const char* glyphs = "QWERTYUIOPASDFGHJKLZXCVBNM1234567890";
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      cv::Point a(static_cast<int>(c * kw + 2), static_cast<int>(r * kh + 2));
      cv::Point b(static_cast<int>((c + 1) * kw - 2), static_cast<int>((r + 1) * kh - 2));
      cv::rectangle(img, a, b, {215, 215, 212}, cv::FILLED);
      const std::string g(1, glyphs[rng.uniform(0, 36)]);
      cv::putText(img, g, a + cv::Point(static_cast<int>(kw * 0.25), static_cast<int>(kh * 0.6)),
                  cv::FONT_HERSHEY_PLAIN, kh / 22.0, {40, 40, 40}, 1, cv::LINE_AA);
    }
  }
  return img;
}

cv::Mat Plaid(cv::Size size, cv::Scalar bgr, cv::RNG& rng) {
  cv::Mat img = NoisyColor(size, bgr, 0.1, 16.0, rng);
  const int period = std::max(6, size.width / 9);
  cv::Mat overlay = img.clone();
  for (int x = 0; x < size.width; x += period)
    cv::rectangle(overlay, {x, 0}, {x + period / 3, size.height}, bgr * 0.45, cv::FILLED);
  for (int y = 0; y < size.height; y += period)
    cv::rectangle(overlay, {0, y}, {size.width, y + period / 3}, bgr * 0.45, cv::FILLED);
  cv::addWeighted(img, 0.45, overlay, 0.55, 0.0, img);
  for (int x = period / 2; x < size.width; x += period)
    cv::line(img, {x, 0}, {x, size.height}, {235, 235, 235}, 1);
  for (int y = period / 2; y < size.height; y += period)
    cv::line(img, {0, y}, {size.width, y}, {235, 235, 235}, 1);
  return img;
}

cv::Mat Denim(cv::Size size, cv::Scalar bgr, cv::RNG& rng) {
  cv::Mat img = NoisyColor(size, bgr, 0.22, 24.0, rng);
  AddGrain(img, 6.0, rng);
  for (int y = 0; y < size.height; y += 3)
    cv::line(img, {0, y}, {size.width, y + 6}, bgr * 0.85, 1);
  return img;
}

cv::Mat Scribbles(cv::Size size, cv::Scalar background, cv::RNG& rng) {
  cv::Mat img = NoisyColor(size, background, 0.04, 60.0, rng);
  const int lines = std::max(3, size.height / 40);
  for (int l = 0; l < lines; ++l) {
    const int y = (l + 1) * size.height / (lines + 1);
    int x = rng.uniform(10, std::max(11, size.width / 6));
    const cv::Scalar ink =
        rng.uniform(0, 3) == 0 ? cv::Scalar(160, 60, 30) : cv::Scalar(40, 40, 40);
    while (x < size.width - 40) {
      std::string word;
      const int len = rng.uniform(2, 8);
      for (int i = 0; i < len; ++i) word += static_cast<char>('a' + rng.uniform(0, 26));
      cv::putText(img, word, {x, y}, cv::FONT_HERSHEY_SCRIPT_SIMPLEX, size.height / 500.0 + 0.4,
                  ink, 1 + size.height / 400, cv::LINE_AA);
      x += static_cast<int>(len * (size.height / 40.0 + 9)) + rng.uniform(10, 30);
    }
  }
  return img;
}

cv::Mat PseudoPhoto(cv::Size size, cv::RNG& rng) {
  cv::Mat img = NoisyColor(
      size, {rng.uniform(60.0, 200.0), rng.uniform(60.0, 200.0), rng.uniform(60.0, 200.0)}, 0.35,
      size.width / 4.0, rng);
  for (int i = 0; i < 40; ++i) {
    const cv::Scalar colour(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256));
    cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const int r = rng.uniform(size.width / 40 + 2, size.width / 8 + 3);
    if (i % 2) {
      cv::circle(img, c, r, colour, cv::FILLED, cv::LINE_AA);
    } else {
      cv::rectangle(img, c, c + cv::Point(r, r * 2 / 3), colour, cv::FILLED, cv::LINE_AA);
    }
  }
  return img;
}

}  // namespace dynorb::synth
