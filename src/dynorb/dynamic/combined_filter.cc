#include "dynorb/dynamic/combined_filter.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <algorithm>
#include <stdexcept>

#include "dynorb/core/timer.h"

namespace dynorb {
namespace {

bool InsideMask(const cv::Mat& mask, const cv::Point2f& pt) {
  if (mask.empty()) return false;
  const int x = std::clamp(static_cast<int>(pt.x + 0.5f), 0, mask.cols - 1);
  const int y = std::clamp(static_cast<int>(pt.y + 0.5f), 0, mask.rows - 1);
  return mask.at<uint8_t>(y, x) != 0;
}

}  // namespace

CombinedFilter::CombinedFilter(std::vector<Part> parts, bool allow_refill)
    : parts_(std::move(parts)), allow_refill_(allow_refill), part_ms_(parts_.size(), 0.0), distrusted_(parts_.size(), 0) {
  if (parts_.empty()) throw std::invalid_argument("CombinedFilter needs at least one filter");
  for (const Part& p : parts_) {
    if (!p.filter)
      throw std::invalid_argument("CombinedFilter: part '" + p.label + "' has no filter");
    if (!(p.max_removed_fraction > 0.0 && p.max_removed_fraction <= 1.0))
      throw std::invalid_argument("CombinedFilter: part '" + p.label + "': max_removed_fraction must be in (0, 1]");
    if (!(p.max_overlap_with_earlier >= 0.0 && p.max_overlap_with_earlier <= 1.0))
      throw std::invalid_argument("CombinedFilter: part '" + p.label + "': max_overlap_with_earlier must be in [0, 1]");
  }
}


cv::Mat CombinedFilter::RegionsMostlyOutside(const cv::Mat& mask, const cv::Mat& earlier, double max_fraction) {
  cv::Mat out = cv::Mat::zeros(mask.size(), CV_8U);
  if (mask.empty()) return out;
  if (earlier.empty()) return mask != 0;  // Nothing to overlap: every region stays.
  cv::Mat labels;
  const int n = cv::connectedComponents(mask != 0, labels, 8, CV_32S);
  std::vector<int> area(n, 0), inside(n, 0);
  const bool has_earlier = !earlier.empty();
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const uint8_t* e = has_earlier ? earlier.ptr<uint8_t>(y) : nullptr;
    for (int x = 0; x < labels.cols; ++x) {
      if (l[x] == 0) continue;
      ++area[l[x]];
      if (e != nullptr && e[x] != 0) ++inside[l[x]];
    }
  }
  std::vector<uint8_t> keep(n, 0);
  for (int i = 1; i < n; ++i) keep[i] = inside[i] <= max_fraction * area[i] ? 255 : 0;
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) o[x] = keep[l[x]];
  }
  return out;
}

bool CombinedFilter::MaskCoversDetections() const {
  if (!allow_refill_) return false;
  return std::all_of(parts_.begin(), parts_.end(),
                     [](const Part& p) { return p.only_inside_mask || p.filter->MaskCoversDetections(); });
}

std::string CombinedFilter::name() const {
  std::string n = "fused(";
  for (size_t i = 0; i < parts_.size(); ++i) n += (i ? " + " : "") + parts_[i].filter->name();
  return n + ")";
}

FilterOutput CombinedFilter::Filter(const FilterInput& input) {
  const size_t n = input.keypoints ? input.keypoints->keypoints.size() : 0;
  FilterOutput out;
  out.keep.assign(n, true);
  out.judged = false;  // Judged when any part judged.
  for (size_t p = 0; p < parts_.size(); ++p) {
    Stopwatch watch;
    FilterOutput part = parts_[p].filter->Filter(input);
    out.judged = out.judged || part.judged;
    out.analysed = out.analysed && part.analysed;  // Analysed when every part analysed.
    part_ms_[p] = watch.ElapsedMs();
    if (part.keep.size() != n)
      throw std::logic_error("filter " + parts_[p].label + " returned a wrong-sized keep");
    if (parts_[p].max_overlap_with_earlier < 1.0 && !part.dynamic_mask.empty()) {
      if (out.dynamic_mask.size() != part.dynamic_mask.size() && !out.dynamic_mask.empty())
        throw std::logic_error("filter " + parts_[p].label + " returned a mask of another size");
      part.dynamic_mask = RegionsMostlyOutside(part.dynamic_mask, out.dynamic_mask, parts_[p].max_overlap_with_earlier);
    }
    // With only_inside_mask, only removals backed by the part's dynamic region count (isolated
    // votes are dropped; an empty mask backs none).
    const bool region_only = parts_[p].only_inside_mask;
    std::vector<bool> keep(n, true);
    size_t candidates = 0, removed = 0;
    for (size_t i = 0; i < n; ++i) {
      keep[i] = part.keep[i] || (region_only && !InsideMask(part.dynamic_mask, input.keypoints->keypoints[i].pt));
      if (out.keep[i]) {
        ++candidates;
        removed += keep[i] ? 0 : 1;
      }
    }
    if (static_cast<double>(removed) > parts_[p].max_removed_fraction * static_cast<double>(candidates)) {
      ++distrusted_[p];
      continue;  // Neither removals nor mask; the overlay is dropped with them.
    }
    for (size_t i = 0; i < n; ++i) out.keep[i] = out.keep[i] && keep[i];
    for (const cv::Point2f& m : part.moving_points) {
      if (!region_only || InsideMask(part.dynamic_mask, m)) out.moving_points.push_back(m);
    }
    if (!part.dynamic_mask.empty()) {
      if (out.dynamic_mask.empty()) {
        out.dynamic_mask = part.dynamic_mask.clone();
      } else {
        cv::bitwise_or(out.dynamic_mask, part.dynamic_mask, out.dynamic_mask);
      }
    }
    if (!part.overlay.empty() && input.bgr != nullptr) {
      if (out.overlay.empty()) {
        out.overlay = part.overlay.clone();
      } else {
        // Pixels this part drew (where its drawing differs from the frame) go over the others'.
        cv::Mat diff, drawn;
        cv::absdiff(part.overlay, *input.bgr, diff);
        cv::transform(diff, drawn, cv::Matx13f(1.f, 1.f, 1.f));
        part.overlay.copyTo(out.overlay, drawn > 0);
      }
    }
  }
  return out;
}

std::vector<std::pair<std::string, double>> CombinedFilter::StageTimings() const {
  std::vector<std::pair<std::string, double>> stages;
  for (size_t p = 0; p < parts_.size(); ++p) {
    stages.emplace_back(parts_[p].label, part_ms_[p]);
    for (const auto& [stage, ms] : parts_[p].filter->StageTimings())
      stages.emplace_back(parts_[p].label + "." + stage, ms);
  }
  return stages;
}

std::vector<std::pair<std::string, std::vector<bool>>> CombinedFilter::CueFlags() const {
  std::vector<std::pair<std::string, std::vector<bool>>> cues;
  for (const Part& part : parts_) {
    for (auto& [cue, flags] : part.filter->CueFlags()) cues.emplace_back(part.label + "." + cue, std::move(flags));
  }
  return cues;
}

}  // namespace dynorb
