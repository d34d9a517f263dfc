// The SLAM map: keyframes, landmarks, the covisibility graph and the spanning tree.
//
// MapData holds the entities (ordered by id, so iteration is deterministic) and the operations
// that keep them consistent; its methods assume the caller holds the map lock. Map owns one
// MapData behind ONE private mutex, reachable only through Read() (shared, for snapshots) and
// Write() (exclusive): long work is snapshot -> solve unlocked -> commit. A correction of the
// whole map (Correct(): loop closure, global BA commit) also waits on that mutex until the frame
// being tracked (BeginFrame()) is done, as ORB-SLAM2's tracking holds its map-update mutex.
#pragma once

#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <vector>

#include "dynorb/map/keyframe.h"
#include "dynorb/map/landmark.h"
#include "dynorb/place_recognition/keyframe_database.h"

namespace dynorb {

class MapData {
 public:
  // Place recognition: with a vocabulary, every keyframe added gets its bag of words and enters
  // the keyframe database (set it before the first keyframe; nullptr: none).
  void SetVocabulary(std::shared_ptr<const Vocabulary> vocabulary) {
    vocabulary_ = std::move(vocabulary);
  }
  const Vocabulary* vocabulary() const { return vocabulary_.get(); }
  const std::shared_ptr<const Vocabulary>& shared_vocabulary() const { return vocabulary_; }
  const KeyframeDatabase& keyframe_database() const { return database_; }
  // Counts corrections that moved keyframes and landmarks at once (loop closures, global BA): a
  // tracker holding poses from before re-anchors them to their reference keyframes when it changes.
  uint64_t correction_epoch() const { return correction_epoch_; }
  // `poses_before`: every keyframe's cam_from_world before the correction (kept for the latest).
  void NoteCorrection(std::map<KeyframeId, Rigid3d> poses_before) {
    ++correction_epoch_;
    poses_before_correction_ = std::move(poses_before);
  }
  // The latest correction's (empty before the first).
  const std::map<KeyframeId, Rigid3d>& poses_before_correction() const {
    return poses_before_correction_;
  }

  // Assigns the id; landmarks vector sized to features. With a vocabulary, a keyframe that comes
  // without its bag of words gets it here (callers compute it before taking the lock).
  KeyframeId AddKeyframe(Keyframe keyframe);
  LandmarkId AddLandmark(Landmark landmark);  // Assigns the id.

  bool HasKeyframe(KeyframeId id) const { return keyframes_.count(id) != 0; }
  bool HasLandmark(LandmarkId id) const { return landmarks_.count(id) != 0; }
  const Keyframe& keyframe(KeyframeId id) const { return keyframes_.at(id); }
  Keyframe& keyframe(KeyframeId id) { return keyframes_.at(id); }
  const Landmark& landmark(LandmarkId id) const { return landmarks_.at(id); }
  Landmark& landmark(LandmarkId id) { return landmarks_.at(id); }
  const std::map<KeyframeId, Keyframe>& keyframes() const { return keyframes_; }
  const std::map<LandmarkId, Landmark>& landmarks() const { return landmarks_; }
  size_t NumKeyframes() const { return keyframes_.size(); }
  size_t NumLandmarks() const { return landmarks_.size(); }

  // Links keypoint `index` of keyframe `kf` to landmark `lm` (both directions).
  void AddObservation(LandmarkId lm, KeyframeId kf, int index);
  // Unlinks; a landmark left without observations, or with one that has no depth (it cannot
  // be located any more), is erased.
  void EraseObservation(LandmarkId lm, KeyframeId kf);
  // Erases a landmark and every reference to it.
  void EraseLandmark(LandmarkId lm);
  // Fuses `from` into `into`: observations move over (unless the keyframe already sees `into`),
  // visibility counters add up, `from` is erased.
  void ReplaceLandmark(LandmarkId from, LandmarkId into);
  // Recomputes normal, distance range and representative descriptor from the observations.
  void UpdateLandmarkGeometry(LandmarkId lm);
  void UpdateLandmarkDescriptor(LandmarkId lm);
  // After a correction moved keyframes (`before` -> `after`, each holding every keyframe of the
  // map): landmark `lm` keeps its position in the camera frame of the keyframe it follows —
  // `follow` (kNoKeyframe: its reference keyframe), or its first observer when that keyframe is
  // gone. False (the landmark unmoved) if it has no observer left.
  bool MoveLandmarkWithKeyframe(LandmarkId lm, const std::map<KeyframeId, Rigid3d>& before,
                                const std::map<KeyframeId, Rigid3d>& after,
                                KeyframeId follow = kNoKeyframe);

  // Recomputes the covisibility edges of `kf` from shared landmarks (weight >= min_weight, or the
  // single best if none reaches it), updates the other side, and attaches `kf` to the spanning
  // tree (parent = best covisible) if it has no parent yet.
  void UpdateConnections(KeyframeId kf, int min_weight = 15);
  std::vector<KeyframeId> BestCovisibles(KeyframeId kf, int n) const;
  // ORB-SLAM2's observation count: an observation with depth counts 2 (it fixes the point alone),
  // one without depth counts 1.
  int WeightedObservations(LandmarkId lm) const;
  // Landmarks of `kf` with WeightedObservations >= min_weighted_observations.
  int NumTrackedLandmarks(KeyframeId kf, int min_weighted_observations) const;
  // Erases a keyframe: its observations, edges, and re-parents its children to its parent.
  // The first keyframe (id 0 / the root) is never erased. Its pose relative to its parent is
  // remembered, so frames that referenced it keep a resolvable pose (ResolveKeyframePose).
  void EraseKeyframe(KeyframeId kf);
  // cam_from_world of a keyframe, also of an erased one (through its parent chain at erase time).
  Rigid3d ResolveKeyframePose(KeyframeId kf) const;
  // The first broken link between keyframes, landmarks and graph edges ("" if none): for tests
  // and debugging.
  std::string FirstInconsistency() const;

 private:
  std::map<KeyframeId, Keyframe> keyframes_;
  std::map<LandmarkId, Landmark> landmarks_;
  // Erased keyframe -> (parent, cam_from_parent_cam at erase time).
  std::map<KeyframeId, std::pair<KeyframeId, Rigid3d>> erased_;
  KeyframeId next_keyframe_id_ = 0;
  LandmarkId next_landmark_id_ = 0;
  std::shared_ptr<const Vocabulary> vocabulary_;
  KeyframeDatabase database_;
  uint64_t correction_epoch_ = 0;
  std::map<KeyframeId, Rigid3d> poses_before_correction_;
};

class Map {
 public:
  template <typename F>
  auto Read(F&& f) const {
    std::shared_lock<std::shared_mutex> lock(mutex_);
    return f(static_cast<const MapData&>(data_));
  }
  template <typename F>
  auto Write(F&& f) {
    std::unique_lock<std::shared_mutex> lock(mutex_);
    return f(data_);
  }

  // Write() for a correction that moves the whole map (MapData::NoteCorrection): it waits until
  // no frame is being tracked, and no frame begins while it waits. A frame's tracking thus sees
  // the map entirely before or entirely after each correction, never a mix of both.
  template <typename F>
  auto Correct(F&& f) {
    std::unique_lock<std::shared_mutex> lock(mutex_);
    ++corrections_waiting_;
    gate_.wait(lock, [this] { return frames_in_progress_ == 0; });
    --corrections_waiting_;
    const WakeOnExit wake{&gate_};  // the frames waiting to begin
    return f(data_);
  }

  // The tracking of one frame, from BeginFrame() until the scope ends (one at a time; frames and
  // corrections on different threads: a thread that holds a scope must not call Correct()).
  class FrameScope {
   public:
    explicit FrameScope(Map* map) : map_(map) {}
    FrameScope(const FrameScope&) = delete;
    FrameScope& operator=(const FrameScope&) = delete;
    ~FrameScope() { map_->EndFrame(); }

   private:
    Map* map_;
  };
  int corrections_waiting() const {
    std::shared_lock<std::shared_mutex> lock(mutex_);
    return corrections_waiting_;
  }
  [[nodiscard]] FrameScope BeginFrame() {
    std::unique_lock<std::shared_mutex> lock(mutex_);
    gate_.wait(lock, [this] { return corrections_waiting_ == 0; });
    ++frames_in_progress_;
    return FrameScope(this);
  }

 private:
  struct WakeOnExit {
    std::condition_variable_any* gate;
    ~WakeOnExit() { gate->notify_all(); }
  };
  void EndFrame() {
    std::unique_lock<std::shared_mutex> lock(mutex_);
    --frames_in_progress_;
    gate_.notify_all();
  }

  mutable std::shared_mutex mutex_;
  std::condition_variable_any gate_;  // frames_in_progress_ / corrections_waiting_ changed
  int frames_in_progress_ = 0;
  int corrections_waiting_ = 0;
  MapData data_;
};

}  // namespace dynorb
