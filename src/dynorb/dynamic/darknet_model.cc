#include "dynorb/dynamic/darknet_model.h"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dynorb/core/error.h"
#include "dynorb/core/text.h"

namespace dynorb {
namespace {

// Channel count limit of a layer (the real models have at most a few thousand): larger counts
// in a corrupt cfg would overflow the size arithmetic.
constexpr int kMaxChannels = 1 << 20;

int IntValue(const DarknetSection& s, const std::string& key, int fallback,
             const std::string& path) {
  auto it = s.values.find(key);
  if (it == s.values.end()) return fallback;
  try {
    return std::stoi(it->second);
  } catch (const std::exception&) {
    throw InputErrorAt(path, s.line,
                       "[" + s.type + "] " + key + " is not an integer: '" + it->second + "'");
  }
}

std::vector<int> IntList(const std::string& text, const DarknetSection& s,
                         const std::string& path) {
  std::vector<int> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      out.push_back(std::stoi(TrimBlanks(item)));
    } catch (const std::exception&) {
      throw InputErrorAt(path, s.line,
                         "[" + s.type + "] expected a list of integers, got '" + text + "'");
    }
  }
  return out;
}

// Number of anchors a [yolo] head predicts per cell: its mask list, else num.
int HeadAnchors(const DarknetSection& yolo, const std::string& path) {
  auto it = yolo.values.find("mask");
  if (it != yolo.values.end()) return static_cast<int>(IntList(it->second, yolo, path).size());
  return IntValue(yolo, "num", 1, path);
}

}  // namespace

std::vector<DarknetSection> ReadDarknetCfg(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot read the darknet cfg");
  std::vector<DarknetSection> sections;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    line = TrimBlanks(line.substr(0, line.find('#')));
    if (line.empty()) continue;
    if (line.front() == '[') {
      if (line.back() != ']')
        throw InputErrorAt(path, number, "malformed section header '" + line + "'");
      sections.push_back({line.substr(1, line.size() - 2), {}, number});
      continue;
    }
    const size_t eq = line.find('=');
    if (eq == std::string::npos || sections.empty()) {
      throw InputErrorAt(path, number,
                         "expected 'key=value' inside a [section], got '" + line + "'");
    }
    sections.back().values[TrimBlanks(line.substr(0, eq))] = TrimBlanks(line.substr(eq + 1));
  }
  if (sections.empty() || sections.front().type != "net") {
    throw InputError(path + ": not a darknet cfg (expected a first [net] section)");
  }
  return sections;
}

size_t DarknetConv::KernelFloats() const {
  return static_cast<size_t>(in_channels / groups) * size * size;
}

size_t DarknetConv::Floats() const {
  return static_cast<size_t>(batch_normalize ? 4 : 1) * filters +
         static_cast<size_t>(filters) * KernelFloats();
}

std::vector<DarknetConv> DarknetConvolutions(const std::vector<DarknetSection>& sections,
                                             const std::string& cfg_path) {
  std::vector<DarknetConv> convs;
  std::vector<int> channels;  // output channels of each layer (sections after [net])
  int current = IntValue(sections[0], "channels", 3, cfg_path);
  for (size_t i = 1; i < sections.size(); ++i) {
    const DarknetSection& s = sections[i];
    const int index = static_cast<int>(i) - 1;
    if (s.type == "convolutional") {
      DarknetConv conv;
      conv.section = i;
      conv.filters = IntValue(s, "filters", 1, cfg_path);
      conv.in_channels = current;
      conv.size = IntValue(s, "size", 1, cfg_path);
      conv.groups = IntValue(s, "groups", 1, cfg_path);
      conv.batch_normalize = IntValue(s, "batch_normalize", 0, cfg_path) != 0;
      if (conv.filters < 1 || conv.size < 1 || conv.filters > kMaxChannels || conv.size > 64) {
        throw InputErrorAt(
            cfg_path, s.line,
            "filters must be 1.." + std::to_string(kMaxChannels) + " and size 1..64");
      }
      if (conv.groups < 1 || current % conv.groups != 0) {
        throw InputErrorAt(cfg_path, s.line,
                           "groups=" + std::to_string(conv.groups) + " does not divide the " +
                               std::to_string(current) + " input channels");
      }
      convs.push_back(conv);
      current = conv.filters;
    } else if (s.type == "route") {
      auto it = s.values.find("layers");
      if (it == s.values.end()) throw InputErrorAt(cfg_path, s.line, "[route] without layers=");
      int64_t sum = 0;
      for (int ref : IntList(it->second, s, cfg_path)) {
        const int64_t abs = ref < 0 ? int64_t{index} + ref : ref;
        if (abs < 0 || abs >= index)
          throw InputErrorAt(cfg_path, s.line, "[route] refers to a missing layer");
        sum += channels[static_cast<size_t>(abs)];
        if (sum > kMaxChannels) {
          throw InputErrorAt(
              cfg_path, s.line,
              "[route] joins more than " + std::to_string(kMaxChannels) + " channels");
        }
      }
      current = static_cast<int>(sum);
    } else if (s.type == "shortcut" || s.type == "maxpool" || s.type == "upsample" ||
               s.type == "yolo" || s.type == "dropout") {
      // Channel count unchanged, no weights.
    } else {
      throw InputErrorAt(cfg_path, s.line, "unsupported darknet layer [" + s.type + "]");
    }
    channels.push_back(current);
  }
  return convs;
}

size_t DarknetWeightsHeaderBytes(const std::string& weights_path) {
  std::ifstream in(weights_path, std::ios::binary);
  int32_t version[3] = {0, 0, 0};
  in.read(reinterpret_cast<char*>(version), sizeof(version));
  if (!in)
    throw InputError(weights_path +
                     ": truncated darknet weights header (expected 3 int32 version fields)");
  const bool wide_seen =
      int64_t{version[0]} * 10 + version[1] >= 2 && version[0] < 1000 && version[1] < 1000;
  return sizeof(version) + (wide_seen ? 8 : 4);
}

size_t DarknetExpectedWeightBytes(const std::string& cfg_path, size_t header_bytes) {
  size_t floats = 0;
  for (const DarknetConv& conv : DarknetConvolutions(ReadDarknetCfg(cfg_path), cfg_path))
    floats += conv.Floats();
  return header_bytes + floats * sizeof(float);
}

DarknetBuffers PruneDarknetClasses(const std::string& cfg_path, const std::string& weights_path,
                                   const std::vector<int>& keep, int names_classes,
                                   const std::string& names_path) {
  const std::vector<DarknetSection> sections = ReadDarknetCfg(cfg_path);
  const std::vector<DarknetConv> convs = DarknetConvolutions(sections, cfg_path);
  const size_t header = DarknetWeightsHeaderBytes(weights_path);
  size_t floats = 0;
  for (const DarknetConv& conv : convs) floats += conv.Floats();
  if (std::filesystem::file_size(weights_path) != header + floats * sizeof(float)) {
    throw InputError(weights_path + ": size does not match " + cfg_path);
  }
  if (keep.empty()) throw InputError(cfg_path + ": class pruning needs at least one class to keep");
  if (keep.front() < 0) throw InputError(cfg_path + ": kept class indices must not be negative");
  for (size_t k = 1; k < keep.size(); ++k) {
    if (keep[k] <= keep[k - 1])
      throw InputError(cfg_path + ": kept class indices must be strictly increasing");
  }
  // Each [yolo] head and the convolution feeding it: per anchor, which of its outputs stay.
  std::map<size_t, std::vector<int>> kept_outputs;  // conv section -> kept output channels
  std::map<size_t, int> heads;                      // yolo section -> its class count
  for (size_t i = 1; i < sections.size(); ++i) {
    if (sections[i].type != "yolo") continue;
    const DarknetSection& yolo = sections[i];
    const int classes = IntValue(yolo, "classes", 20, cfg_path);
    const int anchors = HeadAnchors(yolo, cfg_path);
    if (classes < 1 || classes > 100000 || anchors < 1 || anchors > 1000) {
      throw InputErrorAt(cfg_path, yolo.line, "[yolo] classes or anchor count out of range");
    }
    if (classes != names_classes) {
      throw InputErrorAt(cfg_path, yolo.line,
                         "the head predicts " + std::to_string(classes) + " classes, but " +
                             names_path + " names " + std::to_string(names_classes));
    }
    if (keep.back() >= classes) {
      throw InputErrorAt(cfg_path, yolo.line,
                         "class index " + std::to_string(keep.back()) +
                             " to keep, but the head has " + std::to_string(classes) + " classes");
    }
    const DarknetSection& before = sections[i - 1];
    const int expected = anchors * (5 + classes);
    if (before.type != "convolutional" || IntValue(before, "filters", 1, cfg_path) != expected) {
      throw InputErrorAt(cfg_path, yolo.line,
                         "[yolo] head not fed by a [convolutional] of filters = " +
                             std::to_string(anchors) + " x (5 + " + std::to_string(classes) +
                             ") = " + std::to_string(expected) + "; cannot prune its classes");
    }
    std::vector<int> outputs;
    for (int a = 0; a < anchors; ++a) {
      const int base = a * (5 + classes);
      for (int c = 0; c < 5; ++c) outputs.push_back(base + c);
      for (int k : keep) outputs.push_back(base + 5 + k);
    }
    kept_outputs[i - 1] = outputs;
    heads[i] = classes;
  }
  if (heads.empty()) throw InputError(cfg_path + ": no [yolo] head to prune");

  DarknetBuffers out;
  // The cfg: filters= of the head convolutions and classes= of the heads rewritten, all else as is.
  {
    std::ifstream in(cfg_path);
    std::string line;
    int section = -1;
    while (std::getline(in, line)) {
      const std::string bare = TrimBlanks(line.substr(0, line.find('#')));
      if (!bare.empty() && bare.front() == '[') ++section;
      const size_t eq = bare.find('=');
      const std::string key = eq == std::string::npos ? "" : TrimBlanks(bare.substr(0, eq));
      const size_t s = static_cast<size_t>(std::max(section, 0));
      if (key == "filters" && kept_outputs.count(s)) {
        line = "filters=" + std::to_string(kept_outputs[s].size());
      } else if (key == "classes" && heads.count(s)) {
        line = "classes=" + std::to_string(keep.size());
      }
      out.cfg += line + "\n";
    }
  }
  // The weights: every layer copied, the head convolutions' per-filter arrays and kernels sliced.
  std::ifstream in(weights_path, std::ios::binary);
  std::vector<char> file(header + floats * sizeof(float));
  in.read(file.data(), static_cast<std::streamsize>(file.size()));
  if (!in) throw InputError(weights_path + ": cannot read the darknet weights");
  out.weights.assign(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(header));
  auto append = [&out](const float* from, size_t count) {
    const char* bytes = reinterpret_cast<const char*>(from);
    out.weights.insert(out.weights.end(), bytes, bytes + count * sizeof(float));
  };
  const float* src = reinterpret_cast<const float*>(file.data() + header);
  for (const DarknetConv& conv : convs) {
    auto it = kept_outputs.find(conv.section);
    if (it == kept_outputs.end()) {
      append(src, conv.Floats());
    } else {
      const int arrays = conv.batch_normalize ? 4 : 1;  // biases [, scales, means, variances]
      for (int a = 0; a < arrays; ++a) {
        for (int f : it->second) append(src + static_cast<size_t>(a) * conv.filters + f, 1);
      }
      const float* kernels = src + static_cast<size_t>(arrays) * conv.filters;
      const size_t kf = conv.KernelFloats();
      for (int f : it->second) append(kernels + f * kf, kf);
    }
    src += conv.Floats();
  }
  return out;
}

std::string DarknetCfgWithYoloThreshold(const std::string& cfg, double thresh) {
  std::ostringstream value;
  value.precision(9);
  value << "thresh=" << thresh << "\n";
  std::string out;
  std::istringstream in(cfg);
  std::string line;
  bool in_yolo = false;
  auto close_section = [&] {
    if (in_yolo) out += value.str();  // Last in its section: overrides a thresh= of the file.
  };
  while (std::getline(in, line)) {
    const std::string bare = TrimBlanks(line.substr(0, line.find('#')));
    if (!bare.empty() && bare.front() == '[') {
      close_section();
      in_yolo = bare == "[yolo]";
    }
    out += line + "\n";
  }
  close_section();
  return out;
}

DarknetBuffers ReadDarknetModel(const std::string& cfg_path, const std::string& weights_path) {
  DarknetBuffers model;
  auto read = [](const std::string& path, auto* into) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    const std::streamoff size = in ? static_cast<std::streamoff>(in.tellg()) : -1;
    if (size >= 0) {
      into->resize(static_cast<size_t>(size));
      in.seekg(0);
      in.read(into->data(), size);
    }
    if (size < 0 || !in) throw InputError(path + ": cannot read the darknet model file");
  };
  read(cfg_path, &model.cfg);
  read(weights_path, &model.weights);
  return model;
}

}  // namespace dynorb
