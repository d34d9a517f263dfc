// Fuzz target: the objects.txt of a synthetic sequence (which objects stand still at a stamp),
// read by `dynorb run` with the ground-truth masks (apps/dynamic_labels.h): Open, MaskAt and
// StillObjectsAt on a fixed masks.txt and 10x10 mask of object ids 1-3.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "dynamic_labels.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path d = dynorb::fuzz::TempPath("_masks");
    std::filesystem::create_directories(d);
    cv::Mat mask(10, 10, CV_8U, cv::Scalar(0));
    mask(cv::Rect(0, 0, 3, 3)) = 1;
    mask(cv::Rect(4, 4, 3, 3)) = 2;
    mask(cv::Rect(7, 0, 3, 10)) = 3;
    cv::imwrite((d / "m.png").string(), mask);
    std::ofstream(d / "masks.txt") << "1.0 m.png\n2.0 m.png\n";
    return d;
  }();
  dynorb::fuzz::WriteFile((dir / "objects.txt").string(), data, size);
  dynorb::fuzz::AllowInputError([&] {
    const std::optional<dynorb::MaskGroundTruth> truth =
        dynorb::MaskGroundTruth::Open(dir.string(), cv::Size(10, 10));
    if (!truth) return;  // masks.txt is always there; kept for safety
    for (double stamp : {1.0, 1.5, 2.0, 2.004}) {
      const cv::Mat mask = truth->MaskAt(stamp);
      truth->StillObjectsAt(mask, stamp);
    }
  });
  return 0;
}
