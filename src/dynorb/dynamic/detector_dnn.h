// DnnDetector: the real object detectors of the semantic mode, run through OpenCV DNN
// (DNN_BACKEND_OPENCV, DNN_TARGET_CPU), with the exact pre/post-processing of each model of
// ../shared/models (see each folder's SOURCE.txt and docs/semantic_mode.md):
//   darknet  yolo_fastest_1.1 (default), yolo_fastest_1.1_xl, yolo_fastest_1.1_body  320x320
//   ONNX     yolox_nano 416x416, fastestdet 352x352, nanodet_m_320 320x320
// Construction loads and validates the model files (a missing, truncated or mismatched file is an
// InputError naming the file, what was expected and how to fetch the models) and runs one
// warm-up inference that checks the output layout. Detect() is not thread-safe (one network);
// use one DnnDetector per thread.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include "dynorb/dynamic/darknet_model.h"
#include "dynorb/dynamic/detector_decode.h"

namespace dynorb {

enum class ModelFamily { kDarknetYolo, kYolox, kFastestDet, kNanoDet };

struct ModelSpec {
  std::string name;         // Folder name under the models directory.
  ModelFamily family;
  std::string model_file;   // .weights or .onnx
  std::string config_file;  // darknet .cfg (empty for ONNX)
  std::string names_file;   // one class name per line
  cv::Size input;           // network input size
};

// The supported models, default first.
const std::vector<ModelSpec>& SupportedModels();
// Throws InputError listing the supported names.
const ModelSpec& FindModelSpec(const std::string& name);
// --models resolution: `flag` if given, else $DYNORB_MODELS, else ../shared/models (relative to
// the working directory) when it exists, else the shared/models beside this source checkout when
// it exists, else models/.
std::string ResolveModelsDir(const std::string& flag);
// One spelling per class: COCO's and darknet's aliases (motorcycle = motorbike, airplane =
// aeroplane, couch = sofa, tv = tvmonitor, dining table = diningtable, potted plant =
// pottedplant) and the body model's "body" map to the names of the models' names files.
std::string CanonicalClassName(const std::string& name);
// The 80 COCO class names in the order of the models' outputs.
const std::vector<std::string>& CocoClassNames();

struct DetectorOptions {
  std::string model = "yolo_fastest_1.1";  // one of SupportedModels()
  std::string models_dir = "models";       // folder holding <model>/<files>
  double score_threshold = 0.3;            // minimum confidence of a detection
  double nms_iou = 0.45;                   // class-wise NMS overlap threshold
  // Network input size in pixels; 0 x 0 = the model's own (SOURCE.txt). Darknet models only
  // (fully convolutional): multiples of 32, e.g. 320 x 256 for 4:3 images instead of 320 x 320.
  int input_width = 0, input_height = 0;
  // Only these classes are detected (names as CanonicalClassName spells them; empty = all): a box
  // takes the best-scoring of them. A darknet model then runs with its [yolo] heads cut to them
  // (`prune_heads`, PruneDarknetClasses: the same scores, less work); the ONNX graphs run whole and
  // their other classes are ignored.
  std::vector<std::string> classes;
  bool prune_heads = true;
  void Validate() const;
};

struct DetectorTiming {
  double preprocess_ms = 0.0;
  double inference_ms = 0.0;
  double postprocess_ms = 0.0;
};

class DnnDetector {
 public:
  explicit DnnDetector(const DetectorOptions& options);
  // Boxes in image pixels after thresholding and NMS, decreasing score.
  std::vector<Detection> Detect(const cv::Mat& bgr);
  // The model's class names (the body model's single class "body" is reported as "person").
  // With DetectorOptions::classes on a pruned darknet model, only the kept classes.
  const std::vector<std::string>& class_names() const { return class_names_; }
  // Whether the network's heads were cut to DetectorOptions::classes.
  bool pruned() const { return pruned_; }
  const ModelSpec& spec() const { return spec_; }
  const DetectorTiming& last_timing() const { return timing_; }

 private:
  std::vector<Detection> Decode(const std::vector<cv::Mat>& outputs, const ResizeTransform& t,
                                cv::Size image);
  void CheckFiles(const std::string& folder);
  std::vector<cv::Mat> Forward(const cv::Mat& bgr, ResizeTransform* transform);

  DetectorOptions options_;
  ModelSpec spec_;
  cv::dnn::Net net_;
  std::vector<std::string> output_names_;
  std::vector<std::string> class_names_;
  std::vector<bool> allowed_;  // per class of the output: detected (empty = all)
  bool pruned_ = false;
  DetectorTiming timing_;
};

}  // namespace dynorb
