// Deterministic synthetic textured test image (tests and benchmarks): a smooth gradient with
// random filled rectangles, circles, triangles and lines of random grey levels, lightly blurred.
// Corners everywhere, no repeated structure. Same (size, seed) → same image.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace dynorb {

inline cv::Mat MakeSyntheticTexture(cv::Size size, uint64_t seed, int n_shapes = 0) {
  cv::RNG rng(seed);
  cv::Mat img(size, CV_8UC1);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      img.at<uint8_t>(y, x) = static_cast<uint8_t>(60 + 80 * x / size.width + 40 * y / size.height);
    }
  }
  if (n_shapes <= 0) n_shapes = size.area() / 400;
  const int max_extent = std::max(8, std::min(size.width, size.height) / 12);
  for (int i = 0; i < n_shapes; ++i) {
    const cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const cv::Scalar grey(rng.uniform(0, 256));
    const int e = rng.uniform(3, max_extent);
    switch (rng.uniform(0, 4)) {
      case 0:
        cv::rectangle(img, c, c + cv::Point(rng.uniform(3, max_extent), e), grey, cv::FILLED);
        break;
      case 1:
        cv::circle(img, c, e / 2 + 2, grey, cv::FILLED, cv::LINE_AA);
        break;
      case 2: {
        std::vector<cv::Point> tri = {c, c + cv::Point(rng.uniform(-e, e), rng.uniform(-e, e)),
                                      c + cv::Point(rng.uniform(-e, e), rng.uniform(-e, e))};
        cv::fillConvexPoly(img, tri, grey, cv::LINE_AA);
        break;
      }
      default:
        cv::line(img, c, c + cv::Point(rng.uniform(-e, e), rng.uniform(-e, e)), grey,
                 rng.uniform(1, 4), cv::LINE_AA);
    }
  }
  cv::GaussianBlur(img, img, cv::Size(3, 3), 0.7);
  return img;
}

}  // namespace dynorb
