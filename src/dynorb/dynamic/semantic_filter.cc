#include "dynorb/dynamic/semantic_filter.h"

#include <algorithm>
#include <tuple>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "dynorb/core/error.h"
#include "dynorb/core/timer.h"

namespace dynorb {
namespace {

constexpr int kCarryWindowRadius = 10;  // Half the 21 px LK window, in full-resolution pixels.

// Whether `a` and `b` (as many objects each) pair up one to one with every pair's boxes at IoU
// >= min_iou: pairs are taken greedily, the highest IoU first.
bool PairUp(const std::vector<DynamicObject>& a, const std::vector<DynamicObject>& b,
            double min_iou) {
  if (a.size() != b.size()) return false;
  std::vector<std::tuple<float, size_t, size_t>> pairs;
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t j = 0; j < b.size(); ++j) {
      const float iou = BoxIou(a[i].detection.box, b[j].detection.box);
      if (iou >= min_iou) pairs.emplace_back(iou, i, j);
    }
  }
  std::stable_sort(pairs.begin(), pairs.end(),
                   [](const auto& x, const auto& y) { return std::get<0>(x) > std::get<0>(y); });
  std::vector<bool> used_a(a.size(), false), used_b(b.size(), false);
  size_t paired = 0;
  for (const auto& [iou, i, j] : pairs) {
    if (used_a[i] || used_b[j]) continue;
    used_a[i] = used_b[j] = true;
    ++paired;
  }
  return paired == a.size();
}

}  // namespace

std::vector<std::string> DefaultDynamicClasses() {
  return {"person", "bicycle", "car",   "motorcycle", "bus",      "truck", "bird",  "cat",
          "dog",    "horse",   "sheep", "cow",        "elephant", "bear",  "zebra", "giraffe"};
}

std::vector<bool> ResolveDynamicClasses(const std::vector<std::string>& wanted,
                                        const std::vector<std::string>& model_names) {
  const std::vector<std::string>& coco = CocoClassNames();
  std::vector<bool> dynamic(model_names.size(), false);
  for (const std::string& name : wanted) {
    const std::string c = CanonicalClassName(name);
    if (std::find(coco.begin(), coco.end(), c) == coco.end()) {
      std::string valid;
      for (const auto& n : coco) valid += (valid.empty() ? "" : ", ") + n;
      throw InputError("semantic.classes: unknown class name '" + name + "' (expected COCO names: " + valid + ")");
    }
    for (size_t i = 0; i < model_names.size(); ++i) {
      if (CanonicalClassName(model_names[i]) == c) dynamic[i] = true;
    }
  }
  return dynamic;
}

void SemanticOptions::Validate() const {
  detector.Validate();
  refine.Validate();
  if (detect_every < 1) throw InputError("semantic.detect_every must be >= 1");
  if (detector_latency < 0 || detector_latency >= detect_every) {
    throw InputError("semantic.detector_latency must be >= 0 and < detect_every (one detection in flight)");
  }
  if (max_carried_frames < 0) throw InputError("semantic.max_carried_frames must be >= 0");
  if (quiet_detect_every < 0 || quiet_detect_every % detect_every != 0) {
    throw InputError("semantic.quiet_detect_every must be 0 (off) or a multiple of detect_every (" +
                     std::to_string(detect_every) + "), got " + std::to_string(quiet_detect_every));
  }
  if (quiet_after_empty < 1) throw InputError("semantic.quiet_after_empty must be >= 1");
  if (steady_detect_every < 0 || steady_detect_every % detect_every != 0) {
    throw InputError(
        "semantic.steady_detect_every must be 0 (off) or a multiple of detect_every (" +
        std::to_string(detect_every) + "), got " + std::to_string(steady_detect_every));
  }
  if (steady_after < 1) throw InputError("semantic.steady_after must be >= 1");
  // Carried objects older than max_carried_frames are dropped: a longer gap between detections
  // would leave people unmasked until the next one.
  if (steady_detect_every > 0 && steady_detect_every + detector_latency - 1 > max_carried_frames) {
    throw InputError("semantic.steady_detect_every (" + std::to_string(steady_detect_every) +
                     ") + detector_latency - 1 must be <= max_carried_frames (" +
                     std::to_string(max_carried_frames) + ")");
  }
  // Below 0.5 one box could overlap two others enough to be paired with either.
  if (!(steady_min_iou >= 0.5 && steady_min_iou <= 1.0))
    throw InputError("semantic.steady_min_iou must be in [0.5, 1]");
  if (carry_grid < 2 || carry_grid > 16) throw InputError("semantic.carry_grid must be in [2, 16]");
  if (carry_downscale != 1 && carry_downscale != 2)
    throw InputError("semantic.carry_downscale must be 1 or 2");
  if (classes.empty()) throw InputError("semantic.classes is empty (no a-priori dynamic class)");
  ResolveDynamicClasses(classes, CocoClassNames());
}

SemanticOptions EveryFrameSchedule(SemanticOptions options) {
  options.detect_every = 1;
  options.detector_latency = 0;
  options.quiet_detect_every = 0;
  options.steady_detect_every = 0;
  return options;
}

DetectorOptions SemanticDetectorOptions(const SemanticOptions& options) {
  DetectorOptions detector = options.detector;
  detector.classes.clear();
  for (const std::string& name : options.classes)
    detector.classes.push_back(CanonicalClassName(name));
  return detector;
}

DetectorMaskProvider::DetectorMaskProvider(const SemanticOptions& options)
    : options_((options.Validate(), options)), detector_(SemanticDetectorOptions(options)) {}

DynamicObjects DetectorMaskProvider::Masks(const MaskQuery& query) {
  DynamicObjects result;
  result.mask = cv::Mat::zeros(query.bgr->size(), CV_8U);
  const cv::Mat no_depth;
  for (const Detection& d : detector_.Detect(*query.bgr)) {  // dynamic classes only
    const RefinedMask refined = AddRefinedBoxMask(d.box, query.depth_m ? *query.depth_m : no_depth,
                                                  options_.refine, 0.f, &result.mask);
    result.objects.push_back({d, refined.depth_m});
  }
  return result;
}

SemanticFilter::SemanticFilter(std::unique_ptr<MaskProvider> provider, const SemanticOptions& options)
    : provider_(std::move(provider)), options_(options) {
  CV_Assert(provider_ != nullptr);
}

cv::Mat SemanticFilter::Downscaled(const cv::Mat& gray) const {
  if (options_.carry_downscale == 1) return gray.clone();
  cv::Mat small;
  cv::pyrDown(gray, small);
  return small;
}

DynamicObjects SemanticFilter::Carry(const DynamicObjects& from, const cv::Mat& from_small,
                                     const cv::Mat& small, cv::Size full,
                                     const cv::Mat& depth_m) const {
  const int scale = options_.carry_downscale;
  DynamicObjects carried;
  carried.mask = cv::Mat::zeros(full, CV_8U);
  if (from_small.empty() || frames_since_detection_ > options_.max_carried_frames) return carried;
  // Up to carry_grid x carry_grid points inside each object's mask and box, all tracked in one LK
  // call (one pyramid per image instead of one per object; LK tracks every point independently).
  std::vector<cv::Point2f> points, moved;
  std::vector<size_t> first(from.objects.size() + 1, 0);
  std::vector<cv::Rect> boxes(from.objects.size());
  for (size_t o = 0; o < from.objects.size(); ++o) {
    first[o] = points.size();
    boxes[o] = cv::Rect(from.objects[o].detection.box) & cv::Rect(0, 0, full.width, full.height);
    const cv::Rect& box = boxes[o];
    if (box.empty()) continue;
    // Points whose whole LK window (10 px around them at full resolution) lies in the mask: a
    // window reaching into the background is pulled towards its motion. Too few of them (a thin
    // or small object): every grid point in the mask.
    const auto in_mask = [&](int x, int y) {
      return from.mask.at<uint8_t>(std::clamp(y, 0, full.height - 1),
                                   std::clamp(x, 0, full.width - 1)) != 0;
    };
    std::vector<cv::Point> inner, any;
    const int g = options_.carry_grid;
    for (int iy = 0; iy < g; ++iy) {
      for (int ix = 0; ix < g; ++ix) {
        const cv::Point p(box.x + (2 * ix + 1) * box.width / (2 * g),
                          box.y + (2 * iy + 1) * box.height / (2 * g));
        if (!in_mask(p.x, p.y)) continue;
        any.push_back(p);
        if (in_mask(p.x - kCarryWindowRadius, p.y - kCarryWindowRadius) &&
            in_mask(p.x + kCarryWindowRadius, p.y - kCarryWindowRadius) &&
            in_mask(p.x - kCarryWindowRadius, p.y + kCarryWindowRadius) &&
            in_mask(p.x + kCarryWindowRadius, p.y + kCarryWindowRadius)) {
          inner.push_back(p);
        }
      }
    }
    const std::vector<cv::Point>& chosen = inner.size() >= 4 ? inner : any;
    if (chosen.size() < 4) continue;  // Too few to trust a median.
    for (const cv::Point& p : chosen)
      points.emplace_back(static_cast<float>(p.x) / scale, static_cast<float>(p.y) / scale);
  }
  first[from.objects.size()] = points.size();
  std::vector<uint8_t> status;
  if (!points.empty()) {
    std::vector<float> error;
    // The same support in full-resolution pixels at either scale: 21 px over 3 levels.
    const int window = scale == 1 ? 21 : 11;
    cv::calcOpticalFlowPyrLK(from_small, small, points, moved, status, error,
                             cv::Size(window, window), scale == 1 ? 3 : 2);
  }
  for (size_t o = 0; o < from.objects.size(); ++o) {
    const DynamicObject& object = from.objects[o];
    if (boxes[o].empty()) continue;
    float dx = 0.f, dy = 0.f;
    std::vector<float> xs, ys;
    for (size_t i = first[o]; i < first[o + 1]; ++i) {
      if (!status[i]) continue;
      xs.push_back((moved[i].x - points[i].x) * scale);
      ys.push_back((moved[i].y - points[i].y) * scale);
    }
    if (!xs.empty()) {
      std::nth_element(xs.begin(), xs.begin() + xs.size() / 2, xs.end());
      std::nth_element(ys.begin(), ys.begin() + ys.size() / 2, ys.end());
      dx = xs[xs.size() / 2];
      dy = ys[ys.size() / 2];
    }
    DynamicObject next = object;
    next.detection.box.x += dx;
    next.detection.box.y += dy;
    const RefinedMask refined =
        AddRefinedBoxMask(next.detection.box, depth_m, options_.refine, object.depth_m, &carried.mask);
    if (refined.depth_m > 0.f) next.depth_m = refined.depth_m;
    carried.objects.push_back(next);
  }
  return carried;
}

bool SemanticFilter::Scheduled(FrameId frame_id) const {
  if (frame_id % static_cast<FrameId>(options_.detect_every) != 0) return false;
  if (options_.quiet_detect_every > 0 && empty_detections_ >= options_.quiet_after_empty)
    return frame_id % static_cast<FrameId>(options_.quiet_detect_every) == 0;
  if (options_.steady_detect_every > 0 && steady_detections_ >= options_.steady_after)
    return frame_id % static_cast<FrameId>(options_.steady_detect_every) == 0;
  return true;
}

void SemanticFilter::CountDetection(const DynamicObjects& detected,
                                    const std::vector<DynamicObject>& carried) {
  empty_detections_ = detected.objects.empty() ? empty_detections_ + 1 : 0;
  // Agreement: as many objects as were carried, paired one to one. An empty scene is the
  // quiet schedule's business, not a steady one.
  const bool agree =
      !detected.objects.empty() && PairUp(detected.objects, carried, options_.steady_min_iou);
  steady_detections_ = agree ? steady_detections_ + 1 : 0;
}

void SemanticFilter::DropPending() {
  pending_.wait();
  pending_ = std::future<DynamicObjects>();
}

FilterOutput SemanticFilter::Filter(const FilterInput& input) {
  CV_Assert(input.bgr && input.gray && input.keypoints);
  const cv::Mat no_depth;
  const cv::Mat& depth = input.depth_m ? *input.depth_m : no_depth;
  Stopwatch watch;
  provider_ms_ = propagation_ms_ = wait_ms_ = 0.0;
  last_was_detection_ = false;
  // The image the next frame's carrying starts from: part of the propagation stage.
  cv::Mat small = Downscaled(*input.gray);
  const double downscale_ms = watch.ElapsedMs();
  if (options_.detector_latency == 0) {
    if (Scheduled(input.frame_id)) {
      MaskQuery query{input.frame_id, input.timestamp_s, input.bgr, input.depth_m};
      DynamicObjects detected = provider_->Masks(query);
      // Compared with the objects as carried to the previous frame (not carried on to this one:
      // the detection replaces them, so that carry is not computed).
      CountDetection(detected, current_.objects);
      current_ = std::move(detected);
      frames_since_detection_ = 0;
      provider_ms_ = watch.ElapsedMs() - downscale_ms;
      propagation_ms_ = downscale_ms;
      last_was_detection_ = true;
    } else {
      ++frames_since_detection_;
      current_ = Carry(current_, previous_small_, small, input.gray->size(), depth);
      propagation_ms_ = watch.ElapsedMs();
    }
  } else {
    // Pipelined: the detection of frame k runs on a worker while frames k+1.. are tracked and is
    // used at frame k + latency (waiting for it if needed: the schedule never depends on timing),
    // carried by flow from frame k to the current one.
    ++frames_since_detection_;
    current_ = Carry(current_, previous_small_, small, input.gray->size(), depth);
    // Ids that come again (a caller going on after the System dropped frames whose front ends
    // had run): a detection started at this id or later belongs to a frame that was dropped; it
    // is waited for and discarded. One started at an earlier, tracked frame stays due.
    if (pending_.valid() && input.frame_id <= pending_frame_) DropPending();
    if (pending_.valid() && input.frame_id >= pending_frame_ + static_cast<FrameId>(options_.detector_latency)) {
      Stopwatch wait;
      DynamicObjects detected = pending_.get();
      wait_ms_ = wait.ElapsedMs();
      CountDetection(detected, pending_carried_);
      provider_ms_ = pending_provider_ms_;
      frames_since_detection_ = static_cast<int>(input.frame_id - pending_frame_);
      current_ = Carry(detected, pending_small_, small, input.gray->size(), depth);
      last_was_detection_ = true;
    }
    propagation_ms_ = watch.ElapsedMs() - wait_ms_;
    if (Scheduled(input.frame_id)) {  // After the pending result arrived: it may end a quiet spell.
      // One detection at a time (the provider is not thread-safe): with increasing ids the
      // previous one was taken at pending_frame_ + latency < this frame; this is a safety net.
      if (pending_.valid()) DropPending();
      pending_frame_ = input.frame_id;
      small.copyTo(pending_small_);
      pending_carried_ = current_.objects;
      pending_ = std::async(std::launch::async, [this, id = input.frame_id, ts = input.timestamp_s,
                                                 bgr = input.bgr->clone(),
                                                 depth_copy = depth.clone()]() {
        Stopwatch detect;
        MaskQuery query{id, ts, &bgr, depth_copy.empty() ? nullptr : &depth_copy};
        DynamicObjects result = provider_->Masks(query);
        pending_provider_ms_ = detect.ElapsedMs();
        return result;
      });
    }
  }
  previous_small_ = std::move(small);

  FilterOutput out;
  const std::vector<cv::KeyPoint>& keypoints = input.keypoints->keypoints;
  out.keep.assign(keypoints.size(), true);
  const cv::Mat& mask = current_.mask;
  for (size_t i = 0; i < keypoints.size() && !mask.empty(); ++i) {
    const int x = std::clamp(static_cast<int>(keypoints[i].pt.x + 0.5f), 0, mask.cols - 1);
    const int y = std::clamp(static_cast<int>(keypoints[i].pt.y + 0.5f), 0, mask.rows - 1);
    if (mask.at<uint8_t>(y, x) != 0) out.keep[i] = false;
  }
  out.dynamic_mask = mask;
  if (input.want_overlay) {
    out.overlay = input.bgr->clone();
    if (!mask.empty()) {
      cv::Mat tint(out.overlay.size(), CV_8UC3, cv::Scalar(0, 0, 255));
      cv::Mat blended;
      cv::addWeighted(out.overlay, 0.6, tint, 0.4, 0.0, blended);
      blended.copyTo(out.overlay, mask);
    }
    for (const DynamicObject& o : current_.objects) {
      cv::rectangle(out.overlay, cv::Rect(o.detection.box),
                    last_was_detection_ ? cv::Scalar(0, 255, 255) : cv::Scalar(255, 128, 0), 2);
    }
  }
  return out;
}

}  // namespace dynorb
