// MaskProvider: one interface for every source of a-priori dynamic-object masks used by the
// semantic mode: the DNN detectors (semantic_detector_provider.h), masks or boxes read from disk
// and the synthetic ground truth as an oracle (mask_file.h).
// A provider is called from one thread at a time (the tracking thread, or the semantic filter's
// detection worker), once per frame it is asked about, in frame order.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "dynorb/core/ids.h"
#include "dynorb/dynamic/detector_decode.h"

namespace dynorb {

struct MaskQuery {
  FrameId frame_id = 0;
  double timestamp_s = 0.0;
  const cv::Mat* bgr = nullptr;      // CV_8UC3
  const cv::Mat* depth_m = nullptr;  // CV_32F metres, 0 = no depth
};

// One a-priori dynamic object of a frame.
struct DynamicObject {
  Detection detection;  // image-pixel box (class -1 when the source has no class, e.g. PNG masks)
  float depth_m = 0.f;  // depth of the object's foreground cluster (0 = unknown)
};

struct DynamicObjects {
  std::vector<DynamicObject> objects;
  cv::Mat mask;  // CV_8U, image size, 255 = dynamic pixel
};

class MaskProvider {
 public:
  virtual ~MaskProvider() = default;
  virtual std::string name() const = 0;
  virtual DynamicObjects Masks(const MaskQuery& query) = 0;
};

}  // namespace dynorb
