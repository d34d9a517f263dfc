#include "dynorb/features/image_pyramid.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace dynorb {

ScaleLevels::ScaleLevels(int n_levels, double factor)
    : scale_factor(factor), log_scale_factor(std::log(factor)) {
  scale.resize(n_levels);
  inv_scale.resize(n_levels);
  sigma2.resize(n_levels);
  inv_sigma2.resize(n_levels);
  double s = 1.0;
  for (int l = 0; l < n_levels; ++l) {
    scale[l] = s;
    inv_scale[l] = 1.0 / s;
    sigma2[l] = s * s;
    inv_sigma2[l] = 1.0 / (s * s);
    s *= factor;
  }
}

ImagePyramid::ImagePyramid(const cv::Mat& image, const ScaleLevels& levels)
    : full_size_(image.size()) {
  const int n = levels.NumLevels();
  levels_.resize(n);
  full_from_level_.assign(n, cv::Point2d(1.0, 1.0));
  levels_[0] = image.clone();
  const int min_size = 2 * kEdgeThreshold + 1;
  for (int l = 1; l < n; ++l) {
    const cv::Size size(static_cast<int>(std::lround(image.cols * levels.inv_scale[l])),
                        static_cast<int>(std::lround(image.rows * levels.inv_scale[l])));
    if (size.width < min_size || size.height < min_size || levels_[l - 1].empty()) break;
    cv::resize(levels_[l - 1], levels_[l], size, 0, 0, cv::INTER_LINEAR);
    full_from_level_[l] = cv::Point2d(static_cast<double>(image.cols) / size.width,
                                      static_cast<double>(image.rows) / size.height);
  }
  if (image.cols < min_size || image.rows < min_size) levels_[0].release();
}

cv::Point2f ImagePyramid::LevelToFull(int l, cv::Point2f p) const {
  const cv::Point2d& k = full_from_level_[l];
  return cv::Point2f(static_cast<float>((p.x + 0.5) * k.x - 0.5),
                     static_cast<float>((p.y + 0.5) * k.y - 0.5));
}

cv::Point2f ImagePyramid::FullToLevel(int l, cv::Point2f p) const {
  const cv::Point2d& k = full_from_level_[l];
  return cv::Point2f(static_cast<float>((p.x + 0.5) / k.x - 0.5),
                     static_cast<float>((p.y + 0.5) / k.y - 0.5));
}

}  // namespace dynorb
