#include "dynorb/io/rgbd_image_io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
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
  std::vector<uchar> bytes;
  {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    const std::streamoff size = in ? static_cast<std::streamoff>(in.tellg()) : -1;
    if (size >= 0) {
      bytes.resize(static_cast<size_t>(size));
      in.seekg(0);
      in.read(reinterpret_cast<char*>(bytes.data()), size);
    }
    if (size < 0 || !in) throw InputError(std::string(what) + " image cannot be read: " + path);
  }
  // A PNG cut short (an interrupted copy) is named here: decoding it would also print libpng's
  // own "Read Error" line before ours. Its end chunk, IEND, is the last 12 bytes (some writers
  // append a little after it).
  static const uchar kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() >= 8 && std::equal(kPngSignature, kPngSignature + 8, bytes.begin())) {
    static const char kEnd[4] = {'I', 'E', 'N', 'D'};
    const size_t tail = std::min<size_t>(bytes.size() - 8, 4096);
    if (std::search(bytes.end() - static_cast<std::ptrdiff_t>(tail), bytes.end(), kEnd, kEnd + 4) ==
        bytes.end()) {
      throw InputError(std::string(what) + " image is truncated (a PNG without its end): " + path);
    }
  }
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, flags);
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
