#include "dynamic_labels.h"

#include <cmath>
#include <filesystem>
#include <map>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "dynorb/core/error.h"
#include "dynorb/core/stats.h"
#include "dynorb/dynamic/pixel.h"
#include "dynorb/features/fast_circle.h"
#include "dynorb/io/text_lines.h"

namespace dynorb {

std::optional<MaskGroundTruth> MaskGroundTruth::Open(const std::string& dataset,
                                                     cv::Size image_size) {
  const std::filesystem::path list = std::filesystem::path(dataset) / "masks.txt";
  if (!std::filesystem::exists(list)) return std::nullopt;
  MaskGroundTruth gt;
  gt.folder_ = dataset;
  gt.image_size_ = image_size;
  gt.masks_ = ReadImageList(list.string());
  const std::filesystem::path objects = std::filesystem::path(dataset) / "objects.txt";
  if (std::filesystem::exists(objects)) {
    gt.has_objects_file_ = true;
    const std::string path = objects.string();
    ForEachDataLine(path, [&](int line, const std::vector<std::string>& fields) {
      if (fields.size() < 3) throw InputError(path + ":" + std::to_string(line) + ": expected 'ts id moving ...'");
      const double stamp = ParseDouble(fields[0], path, line);
      const double id = ParseDouble(fields[1], path, line);
      const double moving = ParseDouble(fields[2], path, line);
      if (id != std::floor(id) || id < 1 || id > 255 || (moving != 0 && moving != 1)) {
        throw InputError(path + ":" + std::to_string(line) + ": id must be 1..255 and moving 0 or 1");
      }
      if (gt.still_ids_.empty() || gt.still_ids_.back().first != stamp) {
        if (!gt.still_ids_.empty() && stamp < gt.still_ids_.back().first) {
          throw InputError(path + ":" + std::to_string(line) + ": timestamps must not decrease");
        }
        gt.still_ids_.push_back({stamp, {}});
      }
      if (moving == 0) gt.still_ids_.back().second.push_back(static_cast<int>(id));
    });
  }
  return gt;
}

cv::Mat MaskGroundTruth::StillObjectsAt(const cv::Mat& mask, double timestamp_s) const {
  if (mask.empty() || still_ids_.empty()) return cv::Mat();
  auto it = std::lower_bound(still_ids_.begin(), still_ids_.end(), timestamp_s - 0.005,
                             [](const auto& entry, double t) { return entry.first < t; });
  if (it == still_ids_.end() || std::abs(it->first - timestamp_s) >= 0.005 || it->second.empty()) return cv::Mat();
  cv::Mat still = cv::Mat::zeros(mask.size(), CV_8U);
  for (int id : it->second) still.setTo(255, mask == id);
  return still;
}

cv::Mat MaskGroundTruth::MaskAt(double timestamp_s) const {
  auto it = std::lower_bound(masks_.begin(), masks_.end(), timestamp_s,
                             [](const StampedPath& m, double t) { return m.timestamp_s < t; });
  const StampedPath* best = nullptr;
  for (auto c : {it, it == masks_.begin() ? it : it - 1}) {
    if (c == masks_.end()) continue;
    if (std::abs(c->timestamp_s - timestamp_s) < 0.005 &&
        (best == nullptr || std::abs(c->timestamp_s - timestamp_s) < std::abs(best->timestamp_s - timestamp_s))) {
      best = &*c;
    }
  }
  if (best == nullptr) return cv::Mat();
  const std::string path = (std::filesystem::path(folder_) / best->path).string();
  cv::Mat mask = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (mask.empty()) throw InputError("cannot read mask " + path);
  if (mask.type() != CV_8UC1) throw InputError(path + ": a mask must be an 8-bit single-channel PNG");
  // A mask of another size would be read at the wrong pixels (the statistics silently wrong).
  if (!image_size_.empty() && mask.size() != image_size_) {
    throw InputError(path + ": the mask is " + std::to_string(mask.cols) + "x" +
                     std::to_string(mask.rows) + " but the images are " +
                     std::to_string(image_size_.width) + "x" + std::to_string(image_size_.height));
  }
  return mask;
}

namespace {

// Does the keypoint's FAST circle at its pyramid level touch an object pixel of `mask` that
// `ignore` (optional) does not cover?
bool CircleTouches(const cv::Mat& mask, const cv::Mat& ignore, const cv::KeyPoint& kp, double level_scale_factor) {
  for (const cv::Point& p : FastCirclePixels(kp, level_scale_factor)) {
    if (p.x < 0 || p.y < 0 || p.x >= mask.cols || p.y >= mask.rows || !mask.at<uint8_t>(p.y, p.x)) continue;
    if (ignore.empty() || !ignore.at<uint8_t>(p.y, p.x)) return true;
  }
  return false;
}

}  // namespace

KeypointsOnObjects CountOnObjects(const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& mask,
                                  const cv::Mat& ignore, double level_scale_factor) {
  KeypointsOnObjects count;
  if (mask.empty()) return count;
  for (const cv::KeyPoint& kp : keypoints) {
    const cv::Point px = NearestPixel(kp.pt, mask.size());
    const bool on = mask.at<uint8_t>(px) != 0 && (ignore.empty() || ignore.at<uint8_t>(px) == 0);
    count.pixel += on ? 1 : 0;
    count.support += on || CircleTouches(mask, ignore, kp, level_scale_factor) ? 1 : 0;
  }
  return count;
}

OriginTruth ClassifyOrigins(const std::vector<LandmarkOrigin>& origins,
                            const MaskGroundTruth& masks) {
  OriginTruth truth;
  truth.object_id.assign(origins.size(), 0);
  cv::Mat mask;  // Of the stamp being visited: origins come in stamp order, one mask at a time.
  double mask_stamp = 0.0;
  bool have_mask = false;
  for (size_t i : KnownOriginsByStamp(origins)) {
    const LandmarkOrigin& o = origins[i];
    if (!have_mask || o.timestamp_s != mask_stamp) {
      mask = masks.MaskAt(o.timestamp_s);
      mask_stamp = o.timestamp_s;
      have_mask = true;
    }
    if (mask.empty()) continue;
    ++truth.with_origin;
    const uint8_t id = mask.at<uint8_t>(NearestPixel(o.keypoint.pt, mask.size()));
    truth.object_id[i] = id;
    if (id == 0) continue;
    ++truth.made_on_objects;
    ++truth.by_object[id];
  }
  return truth;
}

OriginTruth ClassifyErasedLandmarks(const std::vector<ErasedLandmark>& erased,
                                    const MaskGroundTruth& masks) {
  std::vector<LandmarkOrigin> origins;
  origins.reserve(erased.size());
  for (const ErasedLandmark& e : erased) origins.push_back(e.origin);
  return ClassifyOrigins(origins, masks);
}

KeypointTruth ComputeKeypointTruth(const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& mask,
                                   const cv::Mat& ignore, double level_scale_factor) {
  KeypointTruth truth;
  if (mask.empty()) return truth;
  truth.has_mask = true;
  const size_t n = keypoints.size();
  truth.ignored.assign(n, 0);
  truth.on_object.assign(n, 0);
  truth.object_id.assign(n, 0);
  truth.support.assign(n, 0);
  truth.near.assign(n, 0);
  constexpr int r = KeypointLabelStats::kBoundaryPx;
  const cv::Mat element = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
  auto object = [&](int x, int y) {
    return mask.at<uint8_t>(y, x) != 0 && (ignore.empty() || ignore.at<uint8_t>(y, x) == 0);
  };
  for (size_t i = 0; i < n; ++i) {
    const cv::Point px = NearestPixel(keypoints[i].pt, mask.size());
    const int x = px.x, y = px.y;
    if (!ignore.empty() && ignore.at<uint8_t>(y, x) != 0) {
      truth.ignored[i] = 1;
      continue;
    }
    truth.object_id[i] = mask.at<uint8_t>(y, x);
    truth.on_object[i] = truth.object_id[i] != 0;
    truth.support[i] = truth.on_object[i] || CircleTouches(mask, ignore, keypoints[i], level_scale_factor);
    // An object pixel under the elliptic neighbourhood (what cv::dilate with this element sees);
    // the centre is part of it.
    truth.near[i] = truth.on_object[i];
    for (int dy = -r; dy <= r && !truth.near[i]; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        const int u = x + dx, v = y + dy;
        if (u < 0 || v < 0 || u >= mask.cols || v >= mask.rows || !element.at<uint8_t>(dy + r, dx + r)) continue;
        if (object(u, v)) {
          truth.near[i] = 1;
          break;
        }
      }
    }
  }
  return truth;
}

void KeypointLabelStats::Add(const std::vector<cv::KeyPoint>& keypoints, const std::vector<bool>& keep,
                             const cv::Mat& mask, const cv::Mat& ignore) {
  Add(ComputeKeypointTruth(keypoints, mask, ignore, level_scale_factor_), keep);
}

void KeypointLabelStats::Add(const KeypointTruth& truth, const std::vector<bool>& keep) {
  if (!truth.has_mask) return;
  long long tp = 0, fp = 0, fn = 0;
  for (size_t i = 0; i < truth.on_object.size(); ++i) {
    if (truth.ignored[i]) {
      ++ignored_;
      continue;
    }
    const bool on = truth.on_object[i] != 0;
    const bool predicted = !keep.empty() && !keep[i];
    if (predicted && on) ++tp;
    if (on) ++(predicted ? object_tp_ : object_fn_)[truth.object_id[i]];
    if (predicted && !on) {
      ++fp;
      fp_near_ += truth.near[i];
    }
    if (!predicted && on) ++fn;
    if (!predicted && !on) ++tn_;
    const bool support = truth.support[i] != 0;
    support_tp_ += predicted && support ? 1 : 0;
    support_fp_ += predicted && !support ? 1 : 0;
    support_fn_ += !predicted && support ? 1 : 0;
  }
  tp_ += tp;
  fp_ += fp;
  fn_ += fn;
  ++frames_;
  if (tp + fp > 0) frame_precision_.push_back(static_cast<double>(tp) / (tp + fp));
  if (tp + fn > 0) frame_recall_.push_back(static_cast<double>(tp) / (tp + fn));
}

nlohmann::json KeypointLabelStats::ToJson() const {
  // An undefined ratio (nothing to divide by: no keypoint removed, none on a mover) is null.
  auto ratio = [](long long a, long long b) {
    return b > 0 ? nlohmann::json(static_cast<double>(a) / b) : nlohmann::json();
  };
  auto mean = [](const std::vector<double>& values) {
    return values.empty() ? nlohmann::json() : nlohmann::json(Summarize(values).mean);
  };
  nlohmann::json by_object = nlohmann::json::object();
  for (size_t id = 1; id < object_tp_.size(); ++id) {
    if (object_tp_[id] + object_fn_[id] == 0) continue;
    by_object[std::to_string(id)] = {
        {"true_positive", object_tp_[id]},
        {"false_negative", object_fn_[id]},
        {"recall", ratio(object_tp_[id], object_tp_[id] + object_fn_[id])}};
  }
  return {
      {"frames_with_masks", frames_},
      {"by_object", by_object},
      {"true_positive", tp_},
      {"false_positive", fp_},
      {"false_negative", fn_},
      {"true_negative", tn_},
      {"ignored", ignored_},
      {"false_positive_within_3px", fp_near_},
      {"precision_within_3px", ratio(tp_ + fp_near_, tp_ + fp_)},
      {"precision", ratio(tp_, tp_ + fp_)},
      {"recall", ratio(tp_, tp_ + fn_)},
      {"keypoints_on_moving_objects_fraction", ratio(tp_ + fn_, tp_ + fp_ + fn_ + tn_)},
      {"support",
       {{"true_positive", support_tp_},
        {"false_positive", support_fp_},
        {"false_negative", support_fn_},
        {"precision", ratio(support_tp_, support_tp_ + support_fp_)},
        {"recall", ratio(support_tp_, support_tp_ + support_fn_)},
        {"definition",
         "truth = keypoint on an object pixel or its FAST circle at its pyramid level (radius 3 * "
         "scale_factor^octave px) touches an object: the corner is the object's outline and moves "
         "with it"}}},
      {"mean_frame_precision", mean(frame_precision_)},
      {"mean_frame_recall", mean(frame_recall_)},
      {"definition",
       "positive = keypoint removed as dynamic; truth = keypoint on a pixel of a moving-object "
       "mask (id != 0); totals over the frames with masks that the filter judged (a first frame "
       "withheld whole is not); an undefined ratio is null; precision_within_3px also counts a "
       "removed keypoint within 3 px of an object (its FAST circle touches the object's outline) "
       "as correct; by_object: the keypoints on each object id of the mask, removed "
       "(true_positive) and kept (false_negative)"}};
}

cv::Mat DrawKeypointOverlay(const cv::Mat& base, const std::vector<cv::KeyPoint>& keypoints,
                            const std::vector<bool>& keep) {
  cv::Mat out = base.clone();
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const bool kept = keep.empty() || keep[i];
    const cv::Scalar color = kept ? cv::Scalar(0, 200, 0) : cv::Scalar(0, 0, 255);
    cv::circle(out, keypoints[i].pt, kept ? 2 : 3, color, kept ? 1 : 2, cv::LINE_AA);
  }
  return out;
}

}  // namespace dynorb
