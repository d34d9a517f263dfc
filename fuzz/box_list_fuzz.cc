// Fuzz target: box lists of the semantic mode (`semantic: {source: boxes, list: F}`): parsed by
// FileMaskProvider, then turned into masks (depth refinement) on a small frame at a few stamps.
#include <cstddef>
#include <cstdint>

#include <opencv2/core.hpp>

#include "dynorb/dynamic/mask_file.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const cv::Mat bgr(48, 64, CV_8UC3, cv::Scalar(0, 0, 0));
  static const cv::Mat depth = [] {
    cv::Mat d(48, 64, CV_32F, cv::Scalar(3.0f));
    d(cv::Rect(20, 10, 20, 30)) = 1.5f;  // something in front
    d(cv::Rect(0, 0, 8, 8)) = 0.f;       // no depth
    return d;
  }();
  const std::string path = dynorb::fuzz::WriteInput(data, size, ".txt");
  dynorb::fuzz::AllowInputError([&] {
    dynorb::FileMaskProvider provider(path, dynorb::MaskFileKind::kBoxes,
                                      dynorb::DepthRefineOptions(), 0.5);
    for (double stamp : {0.0, 1.0, 2.0, 1e9}) {
      dynorb::MaskQuery query;
      query.timestamp_s = stamp;
      query.bgr = &bgr;
      query.depth_m = &depth;
      provider.Masks(query);
    }
  });
  return 0;
}
