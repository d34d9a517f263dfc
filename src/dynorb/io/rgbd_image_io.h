// Loading the images of an RGB-D frame: 8-bit colour images and 16-bit depth PNGs (TUM/Bonn
// convention: raw value = depth_m * depth_factor, 0 = no measurement). Free functions,
// thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace dynorb {

// Loads a colour image as 8-bit BGR, 3 channels (grey images are expanded). Throws InputError if
// the file is missing or cannot be decoded.
cv::Mat LoadColorImage(const std::string& path);

// Loads a depth PNG and converts it to metres (CV_32F). Throws InputError if the file is missing,
// cannot be decoded, or is not a 16-bit single-channel image.
cv::Mat LoadDepthImageMetres(const std::string& path, double depth_factor);

// depth_m(v, u) = float(raw(v, u) / depth_factor), computed in double and rounded once, so
// raw == depth_factor gives exactly 1.0f; raw 0 stays 0. `raw` must be CV_16UC1.
cv::Mat DepthRawToMetres(const cv::Mat& raw, double depth_factor);

}  // namespace dynorb
