// Darknet models read without OpenCV: the .cfg's sections, which floats of the .weights file belong
// to which convolution, the expected file size (a corrupt or mismatched download is caught before
// OpenCV reads it), and class pruning: the same network with only some classes in its [yolo]
// heads, for OpenCV DNN to load from memory (docs/semantic_mode.md, "Class-pruned heads").
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace dynorb {

struct DarknetSection {
  std::string type;                           // "net", "convolutional", "yolo", ...
  std::map<std::string, std::string> values;  // key=value lines
  int line = 0;                               // line of the [type] header (1-based)
};

// Throws InputError naming the file (and line) for an unreadable or malformed cfg.
std::vector<DarknetSection> ReadDarknetCfg(const std::string& path);

// One [convolutional] section's parameters as stored in the weights file: biases[filters], then
// with batch_normalize scales, rolling means and variances [filters] each, then the kernels
// [filters][in_channels / groups][size][size].
struct DarknetConv {
  size_t section = 0;  // index into ReadDarknetCfg's result
  int filters = 0, in_channels = 0, size = 1, groups = 1;
  bool batch_normalize = false;
  size_t KernelFloats() const;  // one filter's kernel
  size_t Floats() const;        // everything of this layer
};

// The convolutions in file order. Throws InputError for unsupported layers or bad references.
std::vector<DarknetConv> DarknetConvolutions(const std::vector<DarknetSection>& sections,
                                             const std::string& cfg_path);

// Size of the weights file's header (3 int32 version fields + a 4- or 8-byte "seen" counter).
// Throws InputError when the file is shorter than the version fields.
size_t DarknetWeightsHeaderBytes(const std::string& weights_path);

// Expected size in bytes of the darknet weights file for `cfg_path` (header of `header_bytes`
// + one float per parameter). Throws InputError for an unreadable/unsupported cfg.
size_t DarknetExpectedWeightBytes(const std::string& cfg_path, size_t header_bytes);

// A darknet model in memory, as cv::dnn::readNetFromDarknet takes it from buffers.
struct DarknetBuffers {
  std::string cfg;
  std::vector<char> weights;
};

// The two files of a darknet model, read as they are. Throws InputError naming an unreadable file.
DarknetBuffers ReadDarknetModel(const std::string& cfg_path, const std::string& weights_path);

// OpenCV's darknet importer's [yolo] `thresh` when the cfg has none.
constexpr double kDarknetDefaultYoloThresh = 0.2;

// OpenCV's darknet importer zeroes every [yolo] class score below the head's `thresh` (0.2 when
// the cfg has none, as the Yolo-Fastest cfgs). `cfg` with `thresh=<thresh>` as the last line of
// every [yolo] section, so that a lower score threshold can take effect.
std::string DarknetCfgWithYoloThreshold(const std::string& cfg, double thresh);

// The model of `cfg_path` / `weights_path` with only the classes `keep` (indices into the model's
// class list, strictly increasing) in every [yolo] head: the 1x1 convolution before each head
// keeps, per anchor, its 4 box + 1 objectness outputs and the kept classes' outputs (biases and
// kernels sliced), and the head's `classes` becomes keep.size(). Darknet [yolo] scores each class
// with its own logistic, so the kept classes' scores are exactly those of the full model.
// `names_classes`: the number of classes in the model's names file (`names_path`, for messages);
// every head must predict that many. Throws InputError when it does not, when a head does not
// have the layout mask count x (5 + classes), or when a kept index is out of range.
DarknetBuffers PruneDarknetClasses(const std::string& cfg_path, const std::string& weights_path,
                                   const std::vector<int>& keep, int names_classes,
                                   const std::string& names_path);

}  // namespace dynorb
