#include "dynorb/dynamic/detector_dnn.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>

#include "dynorb/core/error.h"
#include "dynorb/core/text.h"
#include "dynorb/core/timer.h"
#include "dynorb/dynamic/darknet_model.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;

const char kFetchHint[] =
    "get the models with `scripts/fetch_models.sh --dest DIR` (downloads from the upstream "
    "repositories at pinned commits and checks sha256) and pass --models DIR";

std::vector<std::string> ReadNames(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot read the class-name file; " + kFetchHint);
  std::vector<std::string> names;
  std::string line;
  while (std::getline(in, line)) {
    line = TrimBlanks(line);
    if (!line.empty()) names.push_back(line);
  }
  if (names.empty()) throw InputError(path + ": class-name file is empty (expected one class name per line)");
  return names;
}

std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

const std::vector<ModelSpec>& SupportedModels() {
  static const std::vector<ModelSpec> specs = {
      {"yolo_fastest_1.1", ModelFamily::kDarknetYolo, "yolo-fastest-1.1.weights", "yolo-fastest-1.1.cfg",
       "coco.names", {320, 320}},
      {"yolo_fastest_1.1_xl", ModelFamily::kDarknetYolo, "yolo-fastest-1.1-xl.weights",
       "yolo-fastest-1.1-xl.cfg", "coco.names", {320, 320}},
      {"yolo_fastest_1.1_body", ModelFamily::kDarknetYolo, "yolo-fastest-1.1_body.weights",
       "yolo-fastest-1.1_body.cfg", "body.names", {320, 320}},
      {"yolox_nano", ModelFamily::kYolox, "yolox_nano.onnx", "", "coco.names", {416, 416}},
      {"fastestdet", ModelFamily::kFastestDet, "FastestDet.onnx", "", "coco.names", {352, 352}},
      {"nanodet_m_320", ModelFamily::kNanoDet, "nanodet.onnx", "", "coco.names", {320, 320}},
  };
  return specs;
}

const ModelSpec& FindModelSpec(const std::string& name) {
  for (const ModelSpec& spec : SupportedModels()) {
    if (spec.name == name) return spec;
  }
  std::vector<std::string> names;
  for (const ModelSpec& spec : SupportedModels()) names.push_back(spec.name);
  throw InputError("unknown detector model '" + name + "' (supported: " + Join(names) + ")");
}

std::string ResolveModelsDir(const std::string& flag) {
  if (!flag.empty()) return flag;
  if (const char* env = std::getenv("DYNORB_MODELS"); env != nullptr && *env != '\0') return env;
  if (fs::is_directory("../shared/models")) return "../shared/models";
#ifdef DYNORB_CHECKOUT_SHARED_MODELS
  if (fs::is_directory(DYNORB_CHECKOUT_SHARED_MODELS)) return DYNORB_CHECKOUT_SHARED_MODELS;
#endif
  return "models";
}

std::string CanonicalClassName(const std::string& name) {
  static const std::map<std::string, std::string> aliases = {
      {"motorcycle", "motorbike"}, {"airplane", "aeroplane"},       {"couch", "sofa"},
      {"tv", "tvmonitor"},         {"dining table", "diningtable"}, {"potted plant", "pottedplant"},
      {"body", "person"}};
  auto it = aliases.find(name);
  return it == aliases.end() ? name : it->second;
}

const std::vector<std::string>& CocoClassNames() {
  static const std::vector<std::string> names = {
      "person", "bicycle", "car", "motorbike", "aeroplane", "bus", "train", "truck", "boat",
      "traffic light", "fire hydrant", "stop sign", "parking meter", "bench", "bird", "cat", "dog",
      "horse", "sheep", "cow", "elephant", "bear", "zebra", "giraffe", "backpack", "umbrella",
      "handbag", "tie", "suitcase", "frisbee", "skis", "snowboard", "sports ball", "kite",
      "baseball bat", "baseball glove", "skateboard", "surfboard", "tennis racket", "bottle",
      "wine glass", "cup", "fork", "knife", "spoon", "bowl", "banana", "apple", "sandwich", "orange",
      "broccoli", "carrot", "hot dog", "pizza", "donut", "cake", "chair", "sofa", "pottedplant", "bed",
      "diningtable", "toilet", "tvmonitor", "laptop", "mouse", "remote", "keyboard", "cell phone",
      "microwave", "oven", "toaster", "sink", "refrigerator", "book", "clock", "vase", "scissors",
      "teddy bear", "hair drier", "toothbrush"};
  return names;
}

void DetectorOptions::Validate() const {
  FindModelSpec(model);
  if (!(score_threshold > 0.f && score_threshold < 1.f)) {
    throw InputError("semantic.score_threshold must be in (0, 1), got " + std::to_string(score_threshold));
  }
  if (!(nms_iou > 0.f && nms_iou <= 1.f)) {
    throw InputError("semantic.nms_iou must be in (0, 1], got " + std::to_string(nms_iou));
  }
  if (input_width == 0 && input_height == 0) return;
  auto valid = [](int v) { return v >= 64 && v <= 1280 && v % 32 == 0; };
  if (!valid(input_width) || !valid(input_height)) {
    throw InputError("semantic.input_width and input_height must both be 0 (the model's size) or " +
                     std::string("multiples of 32 in [64, 1280], got ") +
                     std::to_string(input_width) + " x " + std::to_string(input_height));
  }
  if (FindModelSpec(model).family != ModelFamily::kDarknetYolo) {
    throw InputError("semantic.input_width / input_height: only the darknet models " +
                     std::string("(yolo_fastest_1.1*) take another input size; ") + model +
                     "'s ONNX graph has a fixed one");
  }
}

void DnnDetector::CheckFiles(const std::string& folder) {
  if (!fs::is_directory(folder)) {
    throw InputError("detector model '" + spec_.name + "': folder " + folder + " not found; " + kFetchHint);
  }
  for (const std::string& file : {spec_.model_file, spec_.config_file, spec_.names_file}) {
    if (file.empty()) continue;
    const fs::path path = fs::path(folder) / file;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec) || fs::file_size(path, ec) == 0) {
      throw InputError("detector model '" + spec_.name + "': " + path.string() + " is missing or empty; " +
                       kFetchHint);
    }
  }
  if (spec_.family != ModelFamily::kDarknetYolo) return;
  // Darknet weights carry no shape information: compare the file size with the cfg's parameters.
  const std::string weights = (fs::path(folder) / spec_.model_file).string();
  const std::string cfg = (fs::path(folder) / spec_.config_file).string();
  const size_t expected = DarknetExpectedWeightBytes(cfg, DarknetWeightsHeaderBytes(weights));
  const size_t actual = fs::file_size(weights);
  if (actual != expected) {
    throw InputError(weights + ": " + std::to_string(actual) + " bytes, but " + cfg + " describes a network of " +
                     std::to_string(expected) + " bytes of weights (cfg/weights mismatch or corrupt download); " +
                     kFetchHint);
  }
}

DnnDetector::DnnDetector(const DetectorOptions& options) : options_(options) {
  options_.Validate();
  spec_ = FindModelSpec(options_.model);
  if (options_.input_width > 0) spec_.input = cv::Size(options_.input_width, options_.input_height);
  const std::string folder = (fs::path(options_.models_dir) / spec_.name).string();
  CheckFiles(folder);
  const std::string model_path = (fs::path(folder) / spec_.model_file).string();
  const std::string names_path = (fs::path(folder) / spec_.names_file).string();
  class_names_ = ReadNames(names_path);
  for (std::string& name : class_names_) {
    if (name == "body") name = "person";
  }
  std::vector<int> keep;  // indices of the asked classes
  if (!options_.classes.empty()) {
    for (size_t i = 0; i < class_names_.size(); ++i) {
      const std::string name = CanonicalClassName(class_names_[i]);
      if (std::any_of(options_.classes.begin(), options_.classes.end(),
                      [&](const std::string& c) { return CanonicalClassName(c) == name; })) {
        keep.push_back(static_cast<int>(i));
      }
    }
    if (keep.empty()) {
      throw InputError("detector model '" + spec_.name + "' has none of the classes " +
                       Join(options_.classes) + " (its classes: " + Join(class_names_) + ")");
    }
  }
  const bool prune = spec_.family == ModelFamily::kDarknetYolo && options_.prune_heads &&
                     !keep.empty() && keep.size() < class_names_.size();
  // Below OpenCV's [yolo] score floor the cfg is given the threshold (DarknetCfgWithYoloThreshold).
  const bool low_threshold = spec_.family == ModelFamily::kDarknetYolo &&
                             options_.score_threshold < kDarknetDefaultYoloThresh;
  const std::string cfg_path = (fs::path(folder) / spec_.config_file).string();
  try {
    if (prune || low_threshold) {
      DarknetBuffers model =
          prune ? PruneDarknetClasses(cfg_path, model_path, keep,
                                      static_cast<int>(class_names_.size()), names_path)
                : ReadDarknetModel(cfg_path, model_path);
      if (low_threshold)
        model.cfg = DarknetCfgWithYoloThreshold(model.cfg, options_.score_threshold);
      net_ = cv::dnn::readNetFromDarknet(model.cfg.data(), model.cfg.size(), model.weights.data(),
                                         model.weights.size());
    }
    if (prune) {
      std::vector<std::string> kept;
      for (int i : keep) kept.push_back(class_names_[i]);
      class_names_ = kept;
      pruned_ = true;
    } else if (spec_.family == ModelFamily::kDarknetYolo) {
      if (!low_threshold) net_ = cv::dnn::readNetFromDarknet(cfg_path, model_path);
      if (!keep.empty()) {
        allowed_.assign(class_names_.size(), false);
        for (int i : keep) allowed_[i] = true;
      }
    } else {
      net_ = cv::dnn::readNetFromONNX(model_path);
      if (!keep.empty()) {
        allowed_.assign(class_names_.size(), false);
        for (int i : keep) allowed_[i] = true;
      }
    }
  } catch (const cv::Exception& e) {
    throw InputError(model_path + ": OpenCV DNN cannot load this " +
                     (spec_.family == ModelFamily::kDarknetYolo ? std::string("darknet model")
                                                                : std::string("ONNX model")) +
                     " (corrupt or wrong file?): " + TrimBlanks(e.err) + "; " + kFetchHint);
  }
  if (net_.empty()) throw InputError(model_path + ": OpenCV DNN loaded an empty network; " + kFetchHint);
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  output_names_ = net_.getUnconnectedOutLayersNames();
  // Warm-up on a grey image: checks the output layout against the names file.
  try {
    ResizeTransform t;
    const cv::Mat probe(spec_.input, CV_8UC3, cv::Scalar(114, 114, 114));
    Decode(Forward(probe, &t), t, probe.size());
  } catch (const cv::Exception& e) {
    throw InputError(model_path + ": inference failed (" + TrimBlanks(e.err) + "); expected the " +
                     spec_.name + " model described in its SOURCE.txt; " + kFetchHint);
  }
}

std::vector<cv::Mat> DnnDetector::Forward(const cv::Mat& bgr, ResizeTransform* t) {
  Stopwatch watch;
  cv::Mat blob;
  switch (spec_.family) {
    case ModelFamily::kDarknetYolo:  // plain resize, RGB, /255
      *t = StretchTransform(bgr.size(), spec_.input);
      blob = cv::dnn::blobFromImage(ApplyResize(bgr, *t, {}), 1.0 / 255.0, spec_.input, cv::Scalar(), true, false);
      break;
    case ModelFamily::kYolox:  // top-left letterbox padded with 114, BGR 0..255
      *t = LetterboxTransform(bgr.size(), spec_.input, false);
      blob = cv::dnn::blobFromImage(ApplyResize(bgr, *t, cv::Scalar(114, 114, 114)), 1.0, spec_.input,
                                    cv::Scalar(), false, false);
      break;
    case ModelFamily::kFastestDet:  // plain resize, BGR, /255
      *t = StretchTransform(bgr.size(), spec_.input);
      blob = cv::dnn::blobFromImage(ApplyResize(bgr, *t, {}), 1.0 / 255.0, spec_.input, cv::Scalar(), false, false);
      break;
    case ModelFamily::kNanoDet: {  // centred letterbox, BGR, (x - mean) / std
      *t = LetterboxTransform(bgr.size(), spec_.input, true);
      blob = cv::dnn::blobFromImage(ApplyResize(bgr, *t, cv::Scalar(0, 0, 0)), 1.0, spec_.input,
                                    cv::Scalar(103.53, 116.28, 123.675), false, false);
      const double inv_std[3] = {1.0 / 57.375, 1.0 / 57.12, 1.0 / 58.395};
      const int plane = spec_.input.area();
      float* data = blob.ptr<float>();
      for (int c = 0; c < 3; ++c) {
        for (int i = 0; i < plane; ++i) data[c * plane + i] = static_cast<float>(data[c * plane + i] * inv_std[c]);
      }
      break;
    }
  }
  timing_.preprocess_ms = watch.ElapsedMs();
  watch.Restart();
  net_.setInput(blob);
  std::vector<cv::Mat> outputs;
  net_.forward(outputs, output_names_);
  timing_.inference_ms = watch.ElapsedMs();
  return outputs;
}

std::vector<Detection> DnnDetector::Decode(const std::vector<cv::Mat>& outputs, const ResizeTransform& t,
                                           cv::Size image) {
  const int num_classes = static_cast<int>(class_names_.size());
  auto last_dim = [](const cv::Mat& m) { return m.size[m.dims - 1]; };
  auto expect = [&](bool ok, const std::string& what) {
    if (!ok) {
      throw InputError(spec_.name + ": unexpected network output (" + what + ") for " +
                       std::to_string(num_classes) + " classes of " + spec_.names_file +
                       "; expected the model described in its SOURCE.txt");
    }
  };
  std::vector<Detection> net_boxes;
  const float thr = static_cast<float>(options_.score_threshold);
  switch (spec_.family) {
    case ModelFamily::kDarknetYolo:
      for (const cv::Mat& out : outputs) {
        expect(out.dims == 2 && out.cols == 5 + num_classes, "[yolo] rows of 5 + classes values");
        const auto d = DecodeDarknetRows(out, t.net_size, thr, allowed_);
        net_boxes.insert(net_boxes.end(), d.begin(), d.end());
      }
      break;
    case ModelFamily::kYolox: {
      expect(outputs.size() == 1 && last_dim(outputs[0]) == 5 + num_classes, "1 x anchors x (5 + classes)");
      const int s = t.net_size.area();
      expect(outputs[0].total() == static_cast<size_t>(s / 64 + s / 256 + s / 1024) * (5 + num_classes),
             "anchors of strides 8/16/32");
      net_boxes = DecodeYolox(outputs[0], t.net_size, thr, allowed_);
      break;
    }
    case ModelFamily::kFastestDet:
      expect(outputs.size() == 1 && outputs[0].dims == 4 && outputs[0].size[1] == 5 + num_classes,
             "1 x (5 + classes) x H x W");
      net_boxes = DecodeFastestDet(outputs[0], t.net_size, thr, allowed_);
      break;
    case ModelFamily::kNanoDet: {
      // Pair score and box outputs of each stride by their cell count.
      std::map<size_t, const cv::Mat*> cls_by_cells, reg_by_cells;
      for (const cv::Mat& out : outputs) {
        if (last_dim(out) == num_classes) cls_by_cells[out.total() / num_classes] = &out;
        else reg_by_cells[out.total() / last_dim(out)] = &out;
      }
      expect(!cls_by_cells.empty() && cls_by_cells.size() == reg_by_cells.size(), "cls_score/bbox_pred pairs");
      for (int stride : {8, 16, 32, 64}) {
        const size_t cells = static_cast<size_t>((t.net_size.width + stride - 1) / stride) *
                             ((t.net_size.height + stride - 1) / stride);
        auto c = cls_by_cells.find(cells);
        auto r = reg_by_cells.find(cells);
        if (c == cls_by_cells.end() || r == reg_by_cells.end()) continue;
        const auto d =
            DecodeNanoDetLevel(*c->second, *r->second, stride, t.net_size, thr, allowed_);
        net_boxes.insert(net_boxes.end(), d.begin(), d.end());
      }
      break;
    }
  }
  return NonMaxSuppression(MapToImage(net_boxes, t, image), static_cast<float>(options_.nms_iou));
}

std::vector<Detection> DnnDetector::Detect(const cv::Mat& bgr) {
  CV_Assert(bgr.type() == CV_8UC3);
  ResizeTransform t;
  const std::vector<cv::Mat> outputs = Forward(bgr, &t);
  Stopwatch watch;
  std::vector<Detection> result = Decode(outputs, t, bgr.size());
  timing_.postprocess_ms = watch.ElapsedMs();
  return result;
}

}  // namespace dynorb
