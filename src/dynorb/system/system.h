// System: the SLAM facade. Per frame: ORB detection -> optional KeypointFilter (dynamic modes)
// -> description -> FrameFeatures -> Tracker::ProcessOne -> (new keyframe) LocalMapper.
//
// Pipelining (ProcessFrame with frames ahead): the front ends of the next frames (detection,
// filter, description) run, in frame order, on a worker thread while this frame is tracked and
// mapped, so the filter's and detector's single-threaded parts overlap tracking and bundle
// adjustment. With D frames ahead the worker can keep working through a keyframe's inline
// mapping (≈ 100-150 ms) instead of idling after one frame. A front end started D frames early
// gets the motion prediction known when it was started (the velocity of the frame D+1 before
// it), fixed by design: a pipelined sequential run is deterministic too.
//
// Run modes: kSequential runs the mapper inline right after the frame that created a keyframe
// (deterministic: same input => bit-identical trajectory); kParallel runs it in a worker thread
// fed by a bounded queue (ORB-SLAM2's threading; the Map's one lock keeps it consistent).
// Trajectory(): every tracked frame's pose, stored relative to its reference keyframe and composed
// with that keyframe's final (bundle-adjusted) pose, as ORB-SLAM2 saves trajectories.
// Not thread-safe: one caller feeds frames.
#pragma once

#include <atomic>
#include <deque>
#include <future>
#include <memory>
#include <optional>
#include <mutex>
#include <thread>
#include <vector>

#include "dynorb/core/background_error.h"
#include "dynorb/core/blocking_queue.h"
#include "dynorb/core/trajectory.h"
#include "dynorb/dynamic/keypoint_filter.h"
#include "dynorb/features/orb_extractor.h"
#include "dynorb/loop_closing/loop_closer.h"
#include "dynorb/map/map.h"
#include "dynorb/mapping/local_mapper.h"
#include "dynorb/tracking/tracker.h"

namespace dynorb {

enum class RunMode { kSequential, kParallel };

struct SystemOptions {
  RgbdSensor sensor;
  OrbOptions orb;
  TrackerOptions tracker;
  LocalMapperOptions mapper;
  RunMode run_mode = RunMode::kSequential;
  int mapper_queue_capacity = 3;  // Keyframes waiting for the mapper (parallel mode).
  // After the keypoint filter removed keypoints, detect again on the same pyramid with the
  // removed area excluded (the filter's dynamic mask plus a disk around each removed keypoint),
  // so the whole feature budget lands on the static part of the image. Only for filters whose
  // mask covers what they found (KeypointFilter::MaskCoversDetections: the semantic filter).
  bool refill_filtered = true;
  int refill_disk_px = 10;
  // Pipelined front ends (ProcessFrame with frames ahead) on 1 worker thread (detection, filter,
  // description of a frame one after the other) or 2: detection (grey image, ORB keypoints) on
  // one, the filter, refill and description on the other, each in frame order, so frame k+1 is
  // detected while frame k is filtered. Same results either way (the filter sees the same input).
  // 0 (default): 2 when there is a keypoint filter, 1 without (plain mode: detection and
  // description alone are too light to split; session 31, docs/slam_core.md).
  int front_end_threads = 0;
  // Place recognition (relocalisation over the whole map): keyframes get a bag of words of this
  // vocabulary; nullptr: the built-in one (place_recognition/builtin_vocabulary.h).
  bool place_recognition = true;
  std::shared_ptr<const Vocabulary> vocabulary;
  // Loop closing after each keyframe's local mapping (needs place_recognition).
  LoopClosingOptions loop_closing;
  void Validate() const;  // Throws InputError.
};

struct FrameTiming {
  double detect_ms = 0.0, filter_ms = 0.0, describe_ms = 0.0, track_ms = 0.0, local_map_ms = 0.0;
  double mapping_ms = 0.0;  // Inline mapping (sequential mode) after this frame.
  double refill_ms = 0.0;   // Second detection after filtering (SystemOptions::refill_filtered).
  double total_ms = 0.0;     // What the caller waited in ProcessFrame: the per-frame cost that
                             // bounds the frame rate (pipelined: the front end ran overlapped).
  double latency_ms = 0.0;   // Front end + tracking + inline mapping of this frame (≈ total_ms
                             // when not pipelined).
  std::vector<std::pair<std::string, double>> filter_stages_ms;  // KeypointFilter::StageTimings().
};

struct FrameRecord {
  FrameId id = 0;
  double timestamp_s = 0.0;
  TrackingState state = TrackingState::kNotInitialized;
  bool pose_valid = false;
  bool relocalized = false;
  KeyframeId reference_keyframe = kNoKeyframe;
  Rigid3d cam_from_reference;  // Pose relative to the reference keyframe when tracked.
  int num_keypoints = 0;       // Detected.
  int num_filtered = 0;        // Removed by the keypoint filter.
  int num_refilled = 0;        // Keypoints used after the refill detection (0: no refill).
  int num_used = 0;            // Keypoints handed to tracking (after the filter and the refill).
  int num_with_depth = 0;      // ... of them with depth (initialisation needs enough of both).
  int num_inliers = 0;
  bool new_keyframe = false;
  bool pipelined = false;   // This frame's front end ran on the worker thread (pipelining).
  bool judged = true;       // The filter judged this frame (FilterOutput::judged); false: its
                            // keypoints were withheld if the map was not initialized yet.
  bool analysed = true;     // The filter analysed this frame (FilterOutput::analysed); false: it
                            // carried its earlier result (the FAST cues between analyses).
  FrameTiming timing;
  std::vector<bool> keep;  // Filter decision per detected keypoint (empty without a filter).
  std::vector<cv::KeyPoint> detected;  // Detected keypoints (kept only when record_keypoints).
  std::vector<cv::KeyPoint> inliers;   // The keypoints the pose rests on (only when record_keypoints).
  std::vector<cv::KeyPoint> new_landmarks;  // Keypoints that became landmarks (only when record_keypoints).
  int dynamic_votes = 0;                    // Local landmarks observed moving (dynamic_votes.h).
  int erased_as_dynamic = 0;                // ... erased from the map after repeated votes.
  std::vector<ErasedLandmark> erased_landmarks;  // ... and where they came from (only when
                                                 // record_keypoints).
  // The filter's per-cue flags (KeypointFilter::CueFlags), only when record_keypoints.
  std::vector<std::pair<std::string, std::vector<bool>>> cue_flags;
  cv::Mat filter_overlay;              // The filter's drawing (only when record_overlays).
};

class System {
 public:
  explicit System(const SystemOptions& options, std::unique_ptr<KeypointFilter> filter = nullptr);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // A frame handed in ahead of its turn (ProcessFrame's `next`).
  struct NextFrame {
    double timestamp_s = 0.0;
    cv::Mat bgr, depth_m;        // Shared, not copied: do not write into them until that frame
                                 // has been processed.
    bool want_overlay = false;   // Its filter overlay (set_record_overlays for that frame).
  };
  // bgr: CV_8UC3; depth_m: CV_32F metres (0 = none), same size. With `next` (pipelining), the
  // front end of that frame starts on a worker thread before this frame is tracked; the next
  // call must then pass that same frame (same timestamp), otherwise std::logic_error. Throws
  // InputError for bad images (a bad `next` is reported by this call, before any work).
  const FrameRecord& ProcessFrame(double timestamp_s, const cv::Mat& bgr, const cv::Mat& depth_m,
                                  const NextFrame* next = nullptr);
  // The same with the frames after this one, in order (ahead[0] is the next frame). Their front
  // ends not yet started are queued on the worker; those already started must come in the same
  // order with the same timestamps (otherwise std::logic_error, before any work). A deterministic
  // caller passes the same number of frames ahead each call (fewer only at the end).
  // When a front end throws (e.g. a filter's corrupt mask file), that exception is rethrown by
  // the call for its frame, which is then not processed, and the frames announced after it are
  // dropped: the next call may pass any frame, as after an unpipelined failure. The filter has
  // seen the dropped frames (their front ends ran to the end) and goes on from there; the ids
  // it is given repeat (a semantic filter drops a detection still in flight then).
  const FrameRecord& ProcessFrame(double timestamp_s, const cv::Mat& bgr, const cv::Mat& depth_m,
                                  const std::vector<NextFrame>& ahead);
  // Tracking from ready-made features (tests, external front ends).
  const FrameRecord& ProcessFeatures(double timestamp_s,
                                     std::shared_ptr<const FrameFeatures> features);
  // Waits for the mapper to process every queued keyframe and for a global BA in the background
  // (parallel mode). Idempotent. Rethrows the first exception of the mapper thread or of a
  // background global BA (parallel mode; they stop at their first error). After Finish(),
  // ProcessFrame and ProcessFeatures throw std::logic_error; after a failure of the mapper
  // thread they rethrow its exception.
  void Finish();

  Trajectory FrameTrajectory() const;
  Trajectory KeyframeTrajectory() const;
  const std::vector<FrameRecord>& records() const { return records_; }
  std::vector<MapperStepStats> mapper_stats() const;
  // Loop closures: one entry per keyframe where a loop was detected (closed or not).
  std::vector<LoopStepStats> loop_stats() const;
  // Global bundle adjustments after loop corrections (committed or not), in the order they ended.
  std::vector<GlobalBaStats> global_ba_stats() const;
  size_t NumKeyframes() const;
  size_t NumLandmarks() const;
  const Map& map() const { return map_; }
  void set_record_keypoints(bool on) { record_keypoints_ = on; }
  // Front-end worker threads when pipelined: SystemOptions::front_end_threads, 0 resolved.
  int front_end_threads() const;
  // Asks the filter for its overlay drawing each frame (kept in the latest record only).
  void set_record_overlays(bool on) { record_overlays_ = on; }

 private:
  // Everything before tracking: detection, the filter, refill, description. Touches only the
  // extractor and the filter (never the tracker or the map), so it may run on the worker thread.
  struct FrontEnd {
    FrameRecord record;
    std::shared_ptr<const FrameFeatures> features;
    std::shared_ptr<const FrameFeatures> withheld;  // No keypoints; used when the filter could not
                                                    // judge the frame and the map is not initialized.
    std::vector<cv::Point2f> moving_points;  // FilterOutput::moving_points and the depth, for
    cv::Mat depth_m;                         // the landmarks' dynamic votes.
    double ms = 0.0;
  };
  // The front end's first stage: the grey image and its ORB keypoints (touches only the extractor,
  // which is immutable: may run concurrently with the second stage of an earlier frame).
  struct Detected {
    cv::Mat gray;
    KeypointSet set;
    double detect_ms = 0.0;  // ORB detection
    double ms = 0.0;         // the whole stage
  };
  Detected Detect(const cv::Mat& bgr) const;
  // The second stage: the filter, refill and description.
  FrontEnd FinishFrontEnd(FrameId id, double timestamp_s, const cv::Mat& bgr,
                          const cv::Mat& depth_m, Detected detected,
                          std::optional<Rigid3d> predicted_velocity, bool tracker_initialized,
                          bool want_overlay, bool record_keypoints);
  FrontEnd RunFrontEnd(FrameId id, double timestamp_s, const cv::Mat& bgr, const cv::Mat& depth_m,
                       std::optional<Rigid3d> predicted_velocity, bool tracker_initialized, bool want_overlay);
  void Track(FrameRecord* record, std::shared_ptr<const FrameFeatures> features,
             std::vector<cv::Point2f> moving_points = {}, cv::Mat depth_m = cv::Mat());
  void MapperLoop();
  // Throws std::logic_error after Finish(), and the mapper thread's error once it failed.
  void CheckCanProcess() const;
  // Throws InputError for features the tracker cannot use: other scale levels than the system's,
  // descriptors not one per keypoint, an octave outside the levels.
  static void CheckFeatures(const FrameFeatures* features, int num_levels);

  SystemOptions options_;
  OrbExtractor extractor_;
  std::unique_ptr<KeypointFilter> filter_;
  Map map_;
  Tracker tracker_;
  LocalMapper mapper_;
  LoopCloser loop_closer_;
  std::vector<FrameRecord> records_;
  FrameId next_frame_id_ = 0;
  bool record_keypoints_ = false;
  bool record_overlays_ = false;
  std::optional<Rigid3d> last_velocity_;  // For the filter's motion prediction.

  BlockingQueue<KeyframeId> queue_;
  // Keyframes pushed to the mapper and not yet mapped (queued or in progress): the tracker's
  // "mapper idle" is this being 0 (a flag set after Pop left a moment where a busy mapper looked
  // idle).
  std::atomic<int> mapper_pending_{0};
  std::thread mapper_thread_;
  BackgroundError mapper_error_;  // The mapper thread's first exception (it then stops).
  mutable std::mutex stats_mutex_;
  std::vector<MapperStepStats> mapper_stats_;
  std::vector<LoopStepStats> loop_stats_;
  // Local mapping, then loop closing, of one keyframe (either thread); returns the mapper's stats.
  MapperStepStats MapKeyframe(KeyframeId keyframe);
  bool finished_ = false;
  // Front ends queued or running on the worker thread (pipelining), oldest first.
  struct Pending {
    double timestamp_s = 0.0;
    std::future<FrontEnd> result;
  };
  std::deque<Pending> pending_;
  // The workers: run the queued front ends one after the other, in frame order (the filter
  // carries state from frame to frame). Started on the first pipelined call. With
  // front_end_threads 2, detect_thread_ runs the first stage and front_thread_ waits for it.
  void StartFrontEnd(const NextFrame& frame);
  void StopFrontEndWorker();
  std::unique_ptr<BlockingQueue<std::packaged_task<FrontEnd()>>> front_jobs_;
  std::thread front_thread_;
  std::unique_ptr<BlockingQueue<std::packaged_task<Detected()>>> detect_jobs_;
  std::thread detect_thread_;
};

}  // namespace dynorb
