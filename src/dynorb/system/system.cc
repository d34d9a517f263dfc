#include "dynorb/system/system.h"

#include <opencv2/imgproc.hpp>

#include "dynorb/core/error.h"
#include "dynorb/core/timer.h"
#include "dynorb/place_recognition/builtin_vocabulary.h"

namespace dynorb {

void SystemOptions::Validate() const {
  if (sensor.camera.fx <= 0.0 || sensor.camera.fy <= 0.0 || sensor.camera.width <= 0 ||
      sensor.camera.height <= 0) {
    throw InputError("camera intrinsics and image size must be positive");
  }
  if (sensor.bf <= 0.0 || sensor.th_depth_m <= 0.0)
    throw InputError("Camera.bf and ThDepth must be positive");
  if (mapper_queue_capacity < 1) throw InputError("mapper queue capacity must be >= 1");
  if (refill_disk_px < 0) throw InputError("refill_disk_px must be >= 0");
  if (front_end_threads < 0 || front_end_threads > 2)
    throw InputError("front_end_threads must be 0 (auto), 1 or 2, got " +
                     std::to_string(front_end_threads));
  orb.Validate();
  tracker.Validate();
  mapper.Validate();
}

namespace {

LoopClosingOptions LoopOptionsFor(LoopClosingOptions options, RunMode run_mode) {
  options.global_ba_thread = options.global_ba_thread && run_mode == RunMode::kParallel;
  return options;
}

}  // namespace

System::System(const SystemOptions& options, std::unique_ptr<KeypointFilter> filter)
    : options_((options.Validate(), options)),
      extractor_(options.orb),
      filter_(std::move(filter)),
      tracker_(options.sensor, options.tracker, &map_),
      mapper_(options.sensor, options.mapper, &map_),
      loop_closer_(options.sensor, options.tracker, options.mapper,
                   LoopOptionsFor(options.loop_closing, options.run_mode), &map_),
      queue_(static_cast<size_t>(options.mapper_queue_capacity)) {
  if (options_.place_recognition) {
    map_.Write([&](MapData& map) {
      map.SetVocabulary(options_.vocabulary ? options_.vocabulary : BuiltInVocabulary());
    });
  }
  if (options_.run_mode == RunMode::kParallel)
    mapper_thread_ = std::thread([this] { MapperLoop(); });
}

System::~System() {
  // Errors of background work surface through Finish() or the next ProcessFrame(); a destructor
  // has no one to tell.
  try {
    Finish();
  } catch (...) {
  }
}

int System::front_end_threads() const {
  if (options_.front_end_threads != 0) return options_.front_end_threads;
  return filter_ ? 2 : 1;
}

void System::StopFrontEndWorker() {
  // Front ends nobody will ask for are run to the end and dropped.
  if (detect_jobs_) detect_jobs_->Close();
  if (front_jobs_) front_jobs_->Close();
  if (detect_thread_.joinable()) detect_thread_.join();
  if (front_thread_.joinable()) front_thread_.join();
  detect_jobs_.reset();
  front_jobs_.reset();
  pending_.clear();
}

namespace {

// A worker thread running the jobs of `jobs` in order until it is closed and drained.
template <typename Result>
std::thread StartWorker(std::unique_ptr<BlockingQueue<std::packaged_task<Result()>>>* jobs) {
  // Capacity: never the bound (at most the frames ahead are queued), only a safety net.
  auto queue = std::make_unique<BlockingQueue<std::packaged_task<Result()>>>(1024);
  std::thread worker([raw = queue.get()] {
    std::packaged_task<Result()> job;
    while (raw->Pop(&job)) job();
  });
  // Only once the thread runs (std::thread may throw): a queue without a reader would make the
  // next frame wait for ever.
  *jobs = std::move(queue);
  return worker;
}

}  // namespace

void System::StartFrontEnd(const NextFrame& frame) {
  const bool split = front_end_threads() == 2;
  if (!front_jobs_) front_thread_ = StartWorker(&front_jobs_);
  if (split && !detect_jobs_) detect_thread_ = StartWorker(&detect_jobs_);
  // Started before this frame is tracked: the velocity and tracker state of the frame before.
  // Called while frame next_frame_id_ is being processed, after its own front end was taken.
  const FrameId id = next_frame_id_ + static_cast<FrameId>(pending_.size()) + 1;
  const bool initialized = tracker_.state() != TrackingState::kNotInitialized;
  std::future<Detected> detected;  // Split: stage 1 runs on the detection thread.
  if (split) {
    std::packaged_task<Detected()> detect([this, bgr = frame.bgr] { return Detect(bgr); });
    detected = detect.get_future();
    detect_jobs_->Push(std::move(detect));
  }
  std::packaged_task<FrontEnd()> job([this, id, frame, velocity = last_velocity_, initialized,
                                      record_keypoints = record_keypoints_,
                                      detected = std::move(detected)]() mutable {
    return FinishFrontEnd(id, frame.timestamp_s, frame.bgr, frame.depth_m,
                          detected.valid() ? detected.get() : Detect(frame.bgr), velocity,
                          initialized, frame.want_overlay, record_keypoints);
  });
  pending_.push_back({frame.timestamp_s, job.get_future()});
  front_jobs_->Push(std::move(job));
}

void System::Finish() {
  StopFrontEndWorker();
  if (finished_) return;
  finished_ = true;
  queue_.Close();
  if (mapper_thread_.joinable()) mapper_thread_.join();
  loop_closer_.JoinGlobalBa();
  mapper_error_.Rethrow();
  loop_closer_.WaitForGlobalBa();  // Rethrows a failed global BA's error.
}

void System::CheckFeatures(const FrameFeatures* features, int num_levels) {
  // The tracker indexes one frame's scale levels with another's octaves (projection search).
  if (features == nullptr) throw InputError("ProcessFeatures: no features");
  if (features->levels().NumLevels() != num_levels) {
    throw InputError("ProcessFeatures: features with " +
                     std::to_string(features->levels().NumLevels()) +
                     " scale levels; the system has " + std::to_string(num_levels));
  }
  if (features->size() > 0 && features->descriptors().rows != features->size())
    throw InputError("ProcessFeatures: one descriptor per keypoint expected");
  for (const cv::KeyPoint& kp : features->keypoints()) {
    if (kp.octave < 0 || kp.octave >= num_levels)
      throw InputError("ProcessFeatures: a keypoint's octave " + std::to_string(kp.octave) +
                       " is outside the " + std::to_string(num_levels) + " levels");
  }
}

void System::CheckCanProcess() const {
  if (finished_) throw std::logic_error("System: a frame after Finish()");
  mapper_error_.Rethrow();  // The mapper thread failed: the map can no longer be kept.
  loop_closer_.RethrowGlobalBaError();  // So did a global BA on its own thread.
}

MapperStepStats System::MapKeyframe(KeyframeId keyframe) {
  const MapperStepStats stats = mapper_.ProcessOne(keyframe);
  const LoopStepStats loop = loop_closer_.ProcessOne(keyframe);
  std::lock_guard<std::mutex> lock(stats_mutex_);
  mapper_stats_.push_back(stats);
  if (loop.detected) loop_stats_.push_back(loop);
  return stats;
}

std::vector<GlobalBaStats> System::global_ba_stats() const {
  return loop_closer_.global_ba_stats();
}

std::vector<LoopStepStats> System::loop_stats() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return loop_stats_;
}

void System::MapperLoop() {
  KeyframeId kf;
  while (queue_.Pop(&kf)) {
    const bool ok = mapper_error_.Capture([&] { MapKeyframe(kf); });
    --mapper_pending_;
    if (!ok) {
      queue_.Close();  // The tracker's pushes fail instead of blocking on a full queue.
      return;
    }
  }
}

namespace {

void CheckImages(const cv::Mat& bgr, const cv::Mat& depth_m) {
  if (bgr.type() != CV_8UC3 || depth_m.type() != CV_32FC1 || bgr.size() != depth_m.size()) {
    throw InputError(
        "ProcessFrame expects a CV_8UC3 image and a CV_32FC1 depth map of the same size");
  }
}

}  // namespace

const FrameRecord& System::ProcessFrame(double timestamp_s, const cv::Mat& bgr,
                                        const cv::Mat& depth_m, const NextFrame* next) {
  return ProcessFrame(timestamp_s, bgr, depth_m, next != nullptr ? std::vector<NextFrame>{*next} : std::vector<NextFrame>{});
}

const FrameRecord& System::ProcessFrame(double timestamp_s, const cv::Mat& bgr, const cv::Mat& depth_m,
                                        const std::vector<NextFrame>& ahead) {
  CheckCanProcess();
  CheckImages(bgr, depth_m);
  for (const NextFrame& frame : ahead) CheckImages(frame.bgr, frame.depth_m);
  if (!pending_.empty()) {
    if (pending_.front().timestamp_s != timestamp_s) {
      throw std::logic_error("ProcessFrame: this is not the frame announced as `next` by an earlier call");
    }
    for (size_t j = 0; j + 1 < pending_.size() && j < ahead.size(); ++j) {
      if (pending_[j + 1].timestamp_s != ahead[j].timestamp_s)
        throw std::logic_error("ProcessFrame: the frames ahead are not the ones announced by an earlier call");
    }
  }
  Stopwatch call;
  FrontEnd front;
  if (!pending_.empty()) {
    std::future<FrontEnd> result = std::move(pending_.front().result);
    pending_.pop_front();
    try {
      front = result.get();
    } catch (...) {
      // As when an unpipelined front end throws: this frame is not processed, and neither are
      // the frames announced after it (their front ends are run to the end and dropped).
      StopFrontEndWorker();
      throw;
    }
    front.record.pipelined = true;
  } else {
    front = RunFrontEnd(next_frame_id_, timestamp_s, bgr, depth_m, last_velocity_,
                        tracker_.state() != TrackingState::kNotInitialized, record_overlays_);
  }
  for (size_t j = pending_.size(); j < ahead.size(); ++j) StartFrontEnd(ahead[j]);

  Stopwatch back_end;
  FrameRecord& record = front.record;
  std::shared_ptr<const FrameFeatures> features = std::move(front.features);
  // Never initialize the map from a frame the filter could not judge: withhold its keypoints.
  if (!record.judged && front.withheld && tracker_.state() == TrackingState::kNotInitialized) {
    features = std::move(front.withheld);
    record.keep.assign(record.keep.size(), false);
    record.num_filtered = static_cast<int>(record.keep.size());
    record.num_refilled = 0;
  }
  Track(&record, std::move(features), std::move(front.moving_points), std::move(front.depth_m));
  record.timing.latency_ms = front.ms + back_end.ElapsedMs();
  record.timing.total_ms = call.ElapsedMs();
  if (!records_.empty()) records_.back().filter_overlay.release();  // Keep only the latest drawing.
  records_.push_back(std::move(record));
  return records_.back();
}

System::Detected System::Detect(const cv::Mat& bgr) const {
  Stopwatch total;
  Detected detected;
  cv::cvtColor(bgr, detected.gray, cv::COLOR_BGR2GRAY);
  Stopwatch watch;
  detected.set = extractor_.Detect(detected.gray);
  detected.detect_ms = watch.ElapsedMs();
  detected.ms = total.ElapsedMs();
  return detected;
}

System::FrontEnd System::RunFrontEnd(FrameId id, double timestamp_s, const cv::Mat& bgr,
                                     const cv::Mat& depth_m, std::optional<Rigid3d> predicted_velocity,
                                     bool tracker_initialized, bool want_overlay) {
  return FinishFrontEnd(id, timestamp_s, bgr, depth_m, Detect(bgr), predicted_velocity,
                        tracker_initialized, want_overlay, record_keypoints_);
}

System::FrontEnd System::FinishFrontEnd(FrameId id, double timestamp_s, const cv::Mat& bgr,
                                        const cv::Mat& depth_m, Detected detected,
                                        std::optional<Rigid3d> predicted_velocity,
                                        bool tracker_initialized, bool want_overlay,
                                        bool record_keypoints) {
  Stopwatch total, watch;
  FrontEnd front;
  FrameRecord& record = front.record;
  record.id = id;
  record.timestamp_s = timestamp_s;
  const cv::Mat& gray = detected.gray;
  const KeypointSet& set = detected.set;
  record.timing.detect_ms = detected.detect_ms;
  record.num_keypoints = set.size();
  if (record_keypoints) record.detected = set.keypoints;

  std::vector<bool> keep(set.size(), true);
  KeypointSet refilled;
  if (filter_) {
    watch.Restart();
    FilterInput input;
    input.frame_id = id;
    input.timestamp_s = timestamp_s;
    input.bgr = &bgr;
    input.gray = &gray;
    input.depth_m = &depth_m;
    input.keypoints = &set;
    input.predicted_cam_from_previous_cam = predicted_velocity;
    input.want_overlay = want_overlay;
    FilterOutput out = filter_->Filter(input);
    if (out.keep.size() != keep.size())
      throw std::logic_error("keypoint filter returned a wrong-sized keep vector");
    keep = std::move(out.keep);
    record.judged = out.judged;
    record.analysed = out.analysed;
    record.timing.filter_ms = watch.ElapsedMs();
    record.timing.filter_stages_ms = filter_->StageTimings();
    for (bool k : keep) record.num_filtered += k ? 0 : 1;
    record.keep = keep;
    if (record_keypoints) record.cue_flags = filter_->CueFlags();
    if (want_overlay) record.filter_overlay = out.overlay;
    if (options_.tracker.dynamic_votes_to_erase > 0 && !out.moving_points.empty()) {
      front.moving_points = std::move(out.moving_points);
      front.depth_m = depth_m;
    }
    if (!out.judged) {
      front.withheld = std::make_shared<const FrameFeatures>(
          extractor_.DescribeKept(set, std::vector<bool>(set.size(), false)), depth_m, options_.sensor,
          extractor_.levels());
    }
    // An unjudged frame is not refilled while the map is uninitialized (it will be withheld).
    const bool may_be_withheld = !out.judged && !tracker_initialized;
    if (!may_be_withheld && options_.refill_filtered && record.num_filtered > 0 &&
        filter_->MaskCoversDetections()) {
      watch.Restart();
      cv::Mat exclude = out.dynamic_mask.empty() || out.dynamic_mask.size() != gray.size()
                            ? cv::Mat::zeros(gray.size(), CV_8U)
                            : (out.dynamic_mask != 0);
      for (int i = 0; i < set.size(); ++i) {
        if (!keep[i])
          cv::circle(exclude, set.keypoints[i].pt, options_.refill_disk_px, cv::Scalar(255),
                     cv::FILLED);
      }
      refilled = extractor_.DetectExcluding(set, exclude);
      record.num_refilled = refilled.size();
      record.timing.refill_ms = watch.ElapsedMs();
    }
  }

  watch.Restart();
  const bool use_refill = record.num_refilled > 0;
  const OrbFeatures orb =
      use_refill ? extractor_.DescribeKept(refilled, std::vector<bool>(refilled.size(), true))
                 : extractor_.DescribeKept(set, keep);
  front.features =
      std::make_shared<const FrameFeatures>(orb, depth_m, options_.sensor, extractor_.levels());
  record.timing.describe_ms = watch.ElapsedMs();
  front.ms = detected.ms + total.ElapsedMs();
  return front;
}

const FrameRecord& System::ProcessFeatures(double timestamp_s,
                                           std::shared_ptr<const FrameFeatures> features) {
  CheckCanProcess();
  if (!pending_.empty()) throw std::logic_error("ProcessFeatures after a pipelined ProcessFrame");
  CheckFeatures(features.get(), extractor_.levels().NumLevels());
  Stopwatch total;
  FrameRecord record;
  record.id = next_frame_id_;
  record.timestamp_s = timestamp_s;
  record.num_keypoints = features->size();
  Track(&record, std::move(features));
  record.timing.total_ms = record.timing.latency_ms = total.ElapsedMs();
  records_.push_back(std::move(record));
  return records_.back();
}

void System::Track(FrameRecord* record, std::shared_ptr<const FrameFeatures> features,
                   std::vector<cv::Point2f> moving_points, cv::Mat depth_m) {
  ++next_frame_id_;
  Stopwatch watch;
  const bool mapper_idle = options_.run_mode == RunMode::kSequential || mapper_pending_ == 0;
  record->num_used = features->size();
  for (int i = 0; i < features->size(); ++i)
    record->num_with_depth += features->HasDepth(i) ? 1 : 0;
  Frame frame(record->id, record->timestamp_s, std::move(features));
  if (record->num_keypoints > 0)
    frame.filtered_fraction = static_cast<double>(record->num_filtered) / record->num_keypoints;
  frame.moving_points = std::move(moving_points);
  frame.depth_m = std::move(depth_m);
  const TrackingResult result = tracker_.ProcessOne(std::move(frame), mapper_idle);
  record->timing.track_ms = watch.ElapsedMs();
  record->timing.local_map_ms = result.local_map_ms;
  record->state = result.state;
  record->pose_valid = result.pose_valid;
  record->relocalized = result.relocalized;
  record->num_inliers = result.num_inliers;
  record->reference_keyframe = result.reference_keyframe;
  record->new_keyframe = result.new_keyframe != kNoKeyframe;
  record->dynamic_votes = result.dynamic_votes;
  record->erased_as_dynamic = static_cast<int>(result.erased_as_dynamic.size());
  if (record_keypoints_) record->erased_landmarks = result.erased_as_dynamic;

  if (record_keypoints_) {
    const FrameFeatures& f = *tracker_.last_frame().features;
    if (result.pose_valid) {  // last_frame() is this frame.
      for (int i : result.inlier_keypoints) record->inliers.push_back(f.keypoint(i));
      for (int i : result.new_landmark_keypoints) record->new_landmarks.push_back(f.keypoint(i));
    }
  }
  if (result.pose_valid) {
    // From the tracker, in the same map state as the pose (a loop correction may come between).
    record->cam_from_reference = result.cam_from_reference;
    // Motion prediction for the next frame's filter: cam_k_from_cam_{k-1}.
    const FrameRecord* previous = records_.empty() ? nullptr : &records_.back();
    last_velocity_.reset();
    if (previous != nullptr && previous->pose_valid && previous->id + 1 == record->id) {
      // Both poses in one map state: a loop correction on the mapper thread (parallel mode) may
      // have landed since the tracker expressed this frame's pose.
      last_velocity_ = map_.Read([&](const MapData& map) {
        const Rigid3d previous_pose =
            previous->cam_from_reference * map.ResolveKeyframePose(previous->reference_keyframe);
        const Rigid3d pose =
            map.correction_epoch() == result.correction_epoch
                ? result.cam_from_world
                : result.cam_from_reference * map.ResolveKeyframePose(result.reference_keyframe);
        return pose * previous_pose.Inverse();
      });
    }
  } else {
    last_velocity_.reset();
  }

  if (result.new_keyframe != kNoKeyframe) {
    if (options_.run_mode == RunMode::kSequential) {
      watch.Restart();
      MapKeyframe(result.new_keyframe);
      record->timing.mapping_ms = watch.ElapsedMs();
    } else {
      ++mapper_pending_;  // Before the push: the mapper may take it at once.
      if (!queue_.Push(result.new_keyframe)) --mapper_pending_;
    }
  }
}

Trajectory System::FrameTrajectory() const {
  return map_.Read([&](const MapData& map) {
    Trajectory trajectory;
    for (const FrameRecord& r : records_) {
      if (!r.pose_valid) continue;
      const Rigid3d cam_from_world =
          r.cam_from_reference * map.ResolveKeyframePose(r.reference_keyframe);
      trajectory.push_back({r.timestamp_s, cam_from_world.Inverse()});
    }
    return trajectory;
  });
}

Trajectory System::KeyframeTrajectory() const {
  return map_.Read([&](const MapData& map) {
    Trajectory trajectory;
    for (const auto& [id, kf] : map.keyframes())
      trajectory.push_back({kf.timestamp_s, kf.cam_from_world.Inverse()});
    return trajectory;
  });
}

std::vector<MapperStepStats> System::mapper_stats() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return mapper_stats_;
}

size_t System::NumKeyframes() const {
  return map_.Read([](const MapData& m) { return m.NumKeyframes(); });
}
size_t System::NumLandmarks() const {
  return map_.Read([](const MapData& m) { return m.NumLandmarks(); });
}

}  // namespace dynorb
