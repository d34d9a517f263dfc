#include "dynorb/io/rgbd_image_io.h"

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

cv::Mat ReadImage(const std::string& path, int flags, const char* what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(std::string(what) + " image not found: " + path);
  }
  cv::Mat image;
  try {
    image = cv::imread(path, flags);
  } catch (const cv::Exception& e) {
    throw InputError(std::string(what) + " image cannot be read: " + path + " (" + e.what() + ")");
  }
  if (image.empty()) throw InputError(std::string(what) + " image cannot be read: " + path);
  return image;
}

std::string DescribeType(const cv::Mat& m) {
  static const char* kDepthNames[] = {"8U", "8S", "16U", "16S", "32S", "32F", "64F", "16F"};
  return std::string(kDepthNames[m.depth()]) + " with " + std::to_string(m.channels()) +
         " channel(s)";
}

}  // namespace

cv::Mat LoadColorImage(const std::string& path) {
  cv::Mat image = ReadImage(path, cv::IMREAD_UNCHANGED, "rgb");
  if (image.depth() != CV_8U) {
    throw InputError("rgb image is not 8-bit: " + path + " (" + DescribeType(image) + ")");
  }
  if (image.channels() == 1) {
    cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
  } else if (image.channels() != 3) {
    throw InputError("rgb image has an unsupported channel count: " + path + " (" +
                     DescribeType(image) + ")");
  }
  return image;
}

cv::Mat DepthRawToMetres(const cv::Mat& raw, double depth_factor) {
  CV_Assert(raw.type() == CV_16UC1);
  CV_Assert(std::isfinite(depth_factor) && depth_factor > 0.0);
  // 65536-entry lookup table: one division per possible raw value, exact rounding.
  static thread_local double cached_factor = 0.0;
  static thread_local std::vector<float> table;
  if (cached_factor != depth_factor || table.empty()) {
    table.resize(65536);
    for (int v = 0; v < 65536; ++v) table[v] = static_cast<float>(v / depth_factor);
    cached_factor = depth_factor;
  }
  cv::Mat depth_m(raw.size(), CV_32FC1);
  for (int r = 0; r < raw.rows; ++r) {
    const uint16_t* in = raw.ptr<uint16_t>(r);
    float* out = depth_m.ptr<float>(r);
    for (int c = 0; c < raw.cols; ++c) out[c] = table[in[c]];
  }
  return depth_m;
}

cv::Mat LoadDepthImageMetres(const std::string& path, double depth_factor) {
  const cv::Mat raw = ReadImage(path, cv::IMREAD_UNCHANGED, "depth");
  if (raw.type() != CV_16UC1) {
    throw InputError("depth image must be 16-bit single channel: " + path + " is " +
                     DescribeType(raw));
  }
  return DepthRawToMetres(raw, depth_factor);
}

}  // namespace dynorb
