#include "dynorb/dynamic/mask_file.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

// The whole of `token` as a T (no trailing characters).
template <typename T>
bool ParseWhole(const std::string& token, T* value) {
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, *value);
  return ec == std::errc() && ptr == end;
}

}  // namespace

FileMaskProvider::FileMaskProvider(const std::string& list_path, MaskFileKind kind, const DepthRefineOptions& refine,
                                   double max_time_diff_s)
    : folder_(std::filesystem::path(list_path).parent_path().string()),
      kind_(kind),
      refine_(refine),
      max_time_diff_s_(max_time_diff_s) {
  std::ifstream in(list_path);
  if (!in) throw InputError(list_path + ": cannot read the mask/box list");
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    std::istringstream fields(line);
    double stamp = 0.0;
    if (!(fields >> stamp)) throw InputErrorAt(list_path, number, "expected a timestamp first, got '" + line + "'");
    if (kind_ == MaskFileKind::kMasks) {
      std::string path, extra;
      if (!(fields >> path) || (fields >> extra)) {
        throw InputErrorAt(list_path, number, "expected 'timestamp path/to/mask.png', got '" + line + "'");
      }
      if (!masks_.emplace(stamp, path).second) throw InputErrorAt(list_path, number, "duplicate timestamp");
    } else {
      // Each field read whole: "1.5" is not a class id followed by a score of 0.5.
      std::vector<std::string> tokens;
      for (std::string token; fields >> token;) tokens.push_back(token);
      const std::string usage =
          "expected 'timestamp x y w h [class_id] [score]' with w, h > 0, got '" + line + "'";
      if (tokens.size() < 4 || tokens.size() > 6) throw InputErrorAt(list_path, number, usage);
      float box[4];
      for (int k = 0; k < 4; ++k) {
        if (!ParseWhole(tokens[k], &box[k]) || !std::isfinite(box[k]))
          throw InputErrorAt(list_path, number, usage);
      }
      if (box[2] <= 0.f || box[3] <= 0.f) throw InputErrorAt(list_path, number, usage);
      Detection d;
      d.box = cv::Rect2f(box[0], box[1], box[2], box[3]);
      d.score = 1.f;
      if (tokens.size() >= 5 && (!ParseWhole(tokens[4], &d.class_id) || d.class_id < 0)) {
        throw InputErrorAt(list_path, number,
                           "class_id must be a non-negative integer, got '" + tokens[4] + "'");
      }
      if (tokens.size() == 6 &&
          (!ParseWhole(tokens[5], &d.score) || !(d.score >= 0.f && d.score <= 1.f))) {
        throw InputErrorAt(list_path, number,
                           "score must be a number in [0, 1], got '" + tokens[5] + "'");
      }
      boxes_[stamp].push_back(d);
    }
  }
}

template <typename T>
const T* FileMaskProvider::Nearest(const std::map<double, T>& entries, double timestamp_s) const {
  const T* best = nullptr;
  double best_diff = max_time_diff_s_;
  auto it = entries.lower_bound(timestamp_s - max_time_diff_s_);
  for (; it != entries.end() && it->first <= timestamp_s + max_time_diff_s_; ++it) {
    const double diff = std::abs(it->first - timestamp_s);
    if (diff <= best_diff) best = &it->second, best_diff = diff;
  }
  return best;
}

DynamicObjects FileMaskProvider::Masks(const MaskQuery& query) {
  DynamicObjects result;
  result.mask = cv::Mat::zeros(query.bgr->size(), CV_8U);
  if (kind_ == MaskFileKind::kMasks) {
    const std::string* path = Nearest(masks_, query.timestamp_s);
    if (path == nullptr) return result;
    const std::string full = (std::filesystem::path(folder_) / *path).string();
    const cv::Mat mask = cv::imread(full, cv::IMREAD_UNCHANGED);
    if (mask.empty() || mask.type() != CV_8U || mask.size() != query.bgr->size()) {
      throw InputError(full + ": expected an 8-bit single-channel PNG mask of " + std::to_string(query.bgr->cols) +
                       "x" + std::to_string(query.bgr->rows) + " pixels");
    }
    result.mask = mask != 0;
    return result;
  }
  const std::vector<Detection>* boxes = Nearest(boxes_, query.timestamp_s);
  if (boxes == nullptr) return result;
  const cv::Mat no_depth;
  for (const Detection& d : *boxes) {
    const RefinedMask r = AddRefinedBoxMask(d.box, query.depth_m ? *query.depth_m : no_depth, refine_, 0.f, &result.mask);
    result.objects.push_back({d, r.depth_m});
  }
  return result;
}

}  // namespace dynorb
