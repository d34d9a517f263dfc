#include "dynorb/tracking/tracker.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "dynorb/core/angles.h"
#include "dynorb/core/error.h"
#include "dynorb/core/timer.h"
#include "dynorb/tracking/local_map.h"
#include "dynorb/tracking/relocalizer.h"

namespace dynorb {

void TrackerOptions::Validate() const {
  if (min_init_points < 10 || min_init_depth_points < 3 || motion_radius_px <= 0 ||
      local_map_radius_factor <= 0 || min_frame_inliers < 3 || min_local_map_inliers < 3 ||
      max_local_keyframes < 1 || max_frames_between_keyframes < 1 || reference_ratio <= 0 ||
      reference_ratio > 1 || relocalization_candidates < 1 || relocalization_place_candidates < 0 ||
      close_keyframe_min_frames < 0 || close_tracked_max < 0 || close_untracked_min < 0 ||
      provisional_min_found < 0 || new_close_points < 0 ||
      !(filtered_keyframe_fraction >= 0.0 && filtered_keyframe_fraction <= 1.0)) {
    throw InputError("tracker options out of range (see tracking/tracker_options.h)");
  }
  if (!(filtered_keyframe_min_motion_m >= 0.0) || !(filtered_keyframe_min_rotation_deg >= 0.0)) {
    throw InputError(
        "tracking: filtered_keyframe_min_motion_m and filtered_keyframe_min_rotation_deg must be "
        ">= 0");
  }
  if (!(motion_prior_sigma_m >= 0.0) ||
      !(motion_prior_velocity_gain > 0.0 && motion_prior_velocity_gain <= 1.0)) {
    throw InputError(
        "tracking: motion_prior_sigma_m must be >= 0 and motion_prior_velocity_gain in (0, 1]");
  }
  if (dynamic_votes_to_erase < 0 || !(dynamic_votes.radius_px >= 0.0) ||
      !(dynamic_votes.band_m >= 0.0) || !(dynamic_votes.band_rel >= 0.0)) {
    throw InputError(
        "tracking: dynamic_votes_to_erase, dynamic_vote_radius_px, dynamic_vote_band_m and "
        "dynamic_vote_band_rel must be >= 0");
  }
  pose.Validate();
}

const char* ToString(TrackingState state) {
  switch (state) {
    case TrackingState::kNotInitialized: return "not_initialized";
    case TrackingState::kOk: return "ok";
    case TrackingState::kLost: return "lost";
  }
  return "?";
}

Tracker::Tracker(const RgbdSensor& sensor, const TrackerOptions& options, Map* map)
    : sensor_(sensor),
      options_(options),
      map_(map),
      centre_model_(options.motion_prior_sigma_m, options.motion_prior_velocity_gain) {
  options_.Validate();
}

TrackingResult Tracker::ProcessOne(Frame frame, bool mapper_idle) {
  // No correction (loop, global BA) lands while this frame is tracked: its pose rests on the map
  // either before or after it, and the next frame re-anchors (ReanchorAfterCorrection).
  const Map::FrameScope in_frame = map_->BeginFrame();
  TrackingResult result;
  if (state_ == TrackingState::kNotInitialized) {
    if (Initialize(&frame, &result.new_landmark_keypoints)) {
      state_ = TrackingState::kOk;
      result.new_keyframe = reference_keyframe_;
      result.pose_valid = true;
      result.num_inliers = frame.NumMatches();
    }
    result.state = state_;
    result.cam_from_world = frame.cam_from_world;
    result.reference_keyframe = reference_keyframe_;
    // The frame is its reference keyframe (same pose).
    result.cam_from_reference = frame.cam_from_world * frame.cam_from_world.Inverse();
    if (state_ == TrackingState::kOk) last_frame_ = std::move(frame);
    return result;
  }

  bool ok = false;
  int inliers = 0;
  if (state_ == TrackingState::kOk) {
    ReanchorAfterCorrection();
    RefreshLandmarkPoints(&last_frame_);
    const bool just_relocalized = ever_relocalized_ && frame.id < last_relocalization_frame_ + 2;
    PredictCentre(frame, just_relocalized);
    if (velocity_ && !just_relocalized) {
      ok = TrackWithMotionModel(&frame);
      if (!ok) ok = TrackReferenceKeyframe(&frame);
    } else {
      ok = TrackReferenceKeyframe(&frame);
    }
  } else {
    centre_prior_.reset();
    // Relocalisation finds a pose in the map as it is now: the tracker takes the current
    // correction epoch first, so the next frame does not move the relocalised pose again.
    ReanchorAfterCorrection();
    ok = Relocalize(&frame);
    if (ok) {
      result.relocalized = true;
      ever_relocalized_ = true;
      last_relocalization_frame_ = frame.id;
    }
  }

  if (ok) {
    Stopwatch watch;
    ok = TrackLocalMap(&frame, &inliers, &result);
    result.local_map_ms = watch.ElapsedMs();
  }
  state_ = ok ? TrackingState::kOk : TrackingState::kLost;
  result.state = state_;
  result.num_inliers = inliers;
  if (ok) {
    if (last_frame_.features) velocity_ = frame.cam_from_world * last_frame_.cam_from_world.Inverse();
    UpdateCentreVelocity(frame, result.relocalized);
    result.pose_valid = true;
    result.cam_from_world = frame.cam_from_world;
    for (size_t i = 0; i < frame.landmarks.size(); ++i) {
      if (frame.landmarks[i] != kNoLandmark && !frame.outlier[i]) result.inlier_keypoints.push_back(static_cast<int>(i));
    }
    if (NeedNewKeyframe(frame, mapper_idle)) {
      result.new_keyframe =
          CreateKeyframe(&frame, false, &result.new_landmark_keypoints, &result.erased_as_dynamic);
    }
    // Outliers do not carry over to the next frame's motion-model search.
    for (size_t i = 0; i < frame.landmarks.size(); ++i) {
      if (frame.outlier[i]) frame.landmarks[i] = kNoLandmark;
    }
    result.reference_keyframe = reference_keyframe_;
    last_reference_keyframe_ = reference_keyframe_;
    last_from_reference_ = map_->Read([&](const MapData& map) {
      result.correction_epoch = map.correction_epoch();
      if (reference_keyframe_ == kNoKeyframe) return Rigid3d();
      return frame.cam_from_world * map.ResolveKeyframePose(reference_keyframe_).Inverse();
    });
    result.cam_from_reference = last_from_reference_;
    last_frame_ = std::move(frame);
  } else {
    velocity_.reset();
    centre_model_.Reset();
  }
  return result;
}

void Tracker::PredictCentre(const Frame& frame, bool just_relocalized) {
  centre_prior_.reset();
  if (!centre_model_.enabled() || just_relocalized) return;
  centre_prior_ = centre_model_.Predict(LastFramePoseNow().Inverse().translation,
                                        frame.timestamp_s - last_frame_.timestamp_s);
}

void Tracker::ReanchorAfterCorrection() {
  map_->Read([&](const MapData& map) {
    if (map.correction_epoch() == seen_correction_epoch_) return;
    seen_correction_epoch_ = map.correction_epoch();
    // A loop closure moved the map: the last frame keeps its pose relative to its reference
    // keyframe (or, if that was culled, to the keyframe it was folded into).
    if (last_reference_keyframe_ != kNoKeyframe) {
      last_frame_.cam_from_world =
          last_from_reference_ * map.ResolveKeyframePose(last_reference_keyframe_);
    }
    centre_model_.Reset();
  });
}

Rigid3d Tracker::LastFramePoseNow() const {
  return map_->Read([&](const MapData& map) {
    return map.HasKeyframe(last_reference_keyframe_)
               ? last_from_reference_ * map.keyframe(last_reference_keyframe_).cam_from_world
               : last_frame_.cam_from_world;
  });
}

void Tracker::UpdateCentreVelocity(const Frame& frame, bool relocalized) {
  if (!centre_model_.enabled()) return;
  const double dt = frame.timestamp_s - last_frame_.timestamp_s;
  // After relocalisation the last tracked frame may be anywhere: the velocity starts again.
  if (relocalized || !last_frame_.features || !(dt > 0.0)) {
    centre_model_.Reset();
    return;
  }
  centre_model_.Update(frame.cam_from_world.Inverse().translation,
                       LastFramePoseNow().Inverse().translation, dt);
}

bool Tracker::Initialize(Frame* frame, std::vector<int>* created) {
  const FrameFeatures& f = *frame->features;
  int with_depth = 0;
  for (int i = 0; i < f.size(); ++i) with_depth += f.HasDepth(i) ? 1 : 0;
  // As ORB-SLAM2 (N > 500 keypoints, every one with depth becomes a landmark). Counting only
  // depth-bearing keypoints delayed initialisation by 53 frames when a dynamic filter had removed
  // a close person's keypoints and the far wall was beyond the depth range.
  if (f.size() < options_.min_init_points || with_depth < options_.min_init_depth_points) return false;
  frame->cam_from_world = Rigid3d::Identity();
  CreateKeyframe(frame, /*all_depth_points=*/true, created);
  return true;
}

void Tracker::RefreshLandmarkPoints(Frame* frame) const {
  map_->Read([frame](const MapData& map) {
    for (size_t i = 0; i < frame->landmarks.size(); ++i) {
      const LandmarkId lm = frame->landmarks[i];
      if (lm == kNoLandmark) continue;
      if (map.HasLandmark(lm)) {
        frame->landmark_points[i] = map.landmark(lm).point_in_world;
      } else {
        frame->landmarks[i] = kNoLandmark;
      }
    }
    return 0;
  });
}

int Tracker::OptimizeAndCount(Frame* frame, bool drop_outliers) {
  std::vector<PoseObservation> observations;
  std::vector<int> index;
  for (size_t i = 0; i < frame->landmarks.size(); ++i) {
    if (frame->landmarks[i] == kNoLandmark) continue;
    PoseObservation obs;
    obs.point_in_world = frame->landmark_points[i];
    obs.keypoint = frame->features->Observation(static_cast<int>(i));
    observations.push_back(obs);
    index.push_back(static_cast<int>(i));
  }
  if (observations.size() < 3) return 0;
  if (options_.provisional_min_found > 0) {
    // Landmarks one keyframe created and fewer than provisional_min_found frames confirmed.
    map_->Read([&](const MapData& map) {
      for (size_t k = 0; k < index.size(); ++k) {
        const LandmarkId lm = frame->landmarks[index[k]];
        if (!map.HasLandmark(lm)) continue;
        const Landmark& l = map.landmark(lm);
        observations[k].provisional = l.NumObservations() < 2 && l.num_found < options_.provisional_min_found;
      }
      return 0;
    });
  }
  const PoseOptimizerResult r =
      OptimizePose(sensor_.camera, sensor_.bf, observations, frame->cam_from_world, options_.pose,
                   centre_prior_ ? &*centre_prior_ : nullptr);
  frame->cam_from_world = r.cam_from_world;
  for (size_t k = 0; k < index.size(); ++k) {
    frame->outlier_at_fixed_gates[index[k]] =
        !(r.nominal_inlier.empty() ? r.inlier[k] : r.nominal_inlier[k]);
  }
  for (size_t k = 0; k < index.size(); ++k) {
    frame->outlier[index[k]] = !r.inlier[k];
    if (!r.inlier[k] && drop_outliers) {
      frame->landmarks[index[k]] = kNoLandmark;
      frame->outlier[index[k]] = false;
    }
  }
  return r.num_inliers;
}

bool Tracker::TrackWithMotionModel(Frame* frame) {
  frame->cam_from_world = *velocity_ * last_frame_.cam_from_world;
  frame->ResetMatches();
  int matches = SearchFromLastFrame(frame, last_frame_, sensor_, options_.motion_radius_px, options_.matcher);
  if (matches < options_.min_motion_matches) {
    frame->ResetMatches();
    matches = SearchFromLastFrame(frame, last_frame_, sensor_, 2.0 * options_.motion_radius_px, options_.matcher);
  }
  if (matches < options_.min_motion_matches) return false;
  return OptimizeAndCount(frame, true) >= options_.min_frame_inliers;
}

bool Tracker::TrackReferenceKeyframe(Frame* frame) {
  frame->ResetMatches();
  frame->cam_from_world = last_frame_.cam_from_world;
  const std::vector<FrameLandmarkMatch> matches = map_->Read([&](const MapData& map) {
    if (!map.HasKeyframe(reference_keyframe_)) return std::vector<FrameLandmarkMatch>{};
    return MatchByDescriptor(*frame->features, map.keyframe(reference_keyframe_), map, options_.matcher);
  });
  if (static_cast<int>(matches.size()) < 15) return false;
  for (const FrameLandmarkMatch& m : matches) frame->SetMatch(m.keypoint, m.landmark, m.point_in_world);
  return OptimizeAndCount(frame, true) >= options_.min_frame_inliers;
}

bool Tracker::Relocalize(Frame* frame) {
  Relocalizer relocalizer(sensor_, options_);
  return relocalizer.Relocalize(*map_, frame);
}

bool Tracker::TrackLocalMap(Frame* frame, int* inliers, TrackingResult* result) {
  std::vector<LandmarkId> visible;
  const LocalMap local =
      map_->Read([&](const MapData& map) { return BuildLocalMap(map, *frame, options_.max_local_keyframes); });
  if (local.reference_keyframe != kNoKeyframe) reference_keyframe_ = local.reference_keyframe;
  frame->reference_keyframe = reference_keyframe_;
  const bool recent_reloc = ever_relocalized_ && frame->id < last_relocalization_frame_ + 2;
  SearchLocalMap(frame, local, sensor_,
                 recent_reloc ? options_.relocalized_radius_factor : options_.local_map_radius_factor,
                 options_.matcher, &visible);
  *inliers = OptimizeAndCount(frame, false);
  std::vector<LandmarkSeenMoving> seen;
  if (options_.dynamic_votes_to_erase > 0 && !frame->moving_points.empty()) {
    std::vector<LandmarkId> ids;
    std::vector<Eigen::Vector3d> points;
    ids.reserve(local.landmarks.size());
    points.reserve(local.landmarks.size());
    for (const LandmarkView& lm : local.landmarks) {
      ids.push_back(lm.id);
      points.push_back(lm.point_in_world);
    }
    seen = LandmarksSeenMoving(ids, points, frame->cam_from_world, sensor_.camera,
                               frame->moving_points, frame->depth_m, options_.dynamic_votes);
  }
  result->dynamic_votes = static_cast<int>(seen.size());
  // Visibility statistics feed landmark culling in the mapper; the dynamic votes erase landmarks.
  map_->Write([&](MapData& map) {
    for (LandmarkId lm : visible) {
      if (map.HasLandmark(lm)) ++map.landmark(lm).num_visible;
    }
    for (size_t i = 0; i < frame->landmarks.size(); ++i) {
      const LandmarkId lm = frame->landmarks[i];
      if (lm != kNoLandmark && !frame->outlier[i] && map.HasLandmark(lm))
        ++map.landmark(lm).num_found;
    }
    if (options_.dynamic_votes_to_erase > 0) {
      result->erased_as_dynamic =
          ApplyDynamicVotes(*frame, seen, options_.dynamic_votes_to_erase, &map);
    }
    return 0;
  });
  const int needed = recent_reloc ? options_.min_local_map_inliers_after_reloc : options_.min_local_map_inliers;
  return *inliers >= needed;
}

bool Tracker::MovedFromReference(const Frame& frame,
                                 const std::optional<Rigid3d>& reference_cam_from_world) const {
  const double min_m = options_.filtered_keyframe_min_motion_m;
  const double min_deg = options_.filtered_keyframe_min_rotation_deg;
  if (min_m <= 0.0 && min_deg <= 0.0) return true;
  if (!reference_cam_from_world) return true;
  const Rigid3d reference_from_cam = *reference_cam_from_world * frame.cam_from_world.Inverse();
  return (min_m > 0.0 && reference_from_cam.translation.norm() >= min_m) ||
         (min_deg > 0.0 && RadToDeg(RotationAngleRad(reference_from_cam.rotation)) >= min_deg);
}

bool Tracker::NeedNewKeyframe(const Frame& frame, bool mapper_idle) const {
  std::optional<Rigid3d> reference_cam_from_world;
  const auto [num_keyframes, reference_matches] = map_->Read([&](const MapData& map) {
    const int n = static_cast<int>(map.NumKeyframes());
    const int min_obs = n <= 2 ? 2 : 3;  // Weighted (ORB-SLAM2): a depth observation counts 2.
    const bool has_reference = map.HasKeyframe(reference_keyframe_);
    if (has_reference) reference_cam_from_world = map.keyframe(reference_keyframe_).cam_from_world;
    const int ref = has_reference ? map.NumTrackedLandmarks(reference_keyframe_, min_obs) : 0;
    return std::make_pair(n, ref);
  });
  const int max_frames = options_.max_frames_between_keyframes;
  if (ever_relocalized_ && frame.id < last_relocalization_frame_ + max_frames && num_keyframes > max_frames) {
    return false;
  }
  // Matches are counted inside the unscaled gates, as ORB-SLAM2 would: the pose solve's tighter
  // gates would otherwise insert ~30 % more keyframes (docs/slam_core.md).
  int inliers = 0, tracked_close = 0, untracked_close = 0;
  const FrameFeatures& f = *frame.features;
  for (int i = 0; i < f.size(); ++i) {
    const bool tracked = frame.landmarks[i] != kNoLandmark && !frame.outlier_at_fixed_gates[i];
    inliers += tracked ? 1 : 0;
    if (!f.IsClose(i, sensor_.th_depth_m)) continue;
    if (tracked) {
      ++tracked_close;
    } else {
      ++untracked_close;
    }
  }
  const bool c1a = frame.id >= last_keyframe_frame_ + static_cast<FrameId>(max_frames);
  const bool covered = options_.filtered_keyframe_fraction > 0.0 && c1a &&
                       frame.filtered_fraction >= options_.filtered_keyframe_fraction &&
                       MovedFromReference(frame, reference_cam_from_world);
  const bool need_close =
      (tracked_close < options_.close_tracked_max || covered) &&
      untracked_close > options_.close_untracked_min &&
      frame.id >= last_keyframe_frame_ + static_cast<FrameId>(options_.close_keyframe_min_frames);
  const double ratio = num_keyframes < 2 ? 0.4 : options_.reference_ratio;
  const bool c1b = frame.id >= last_keyframe_frame_ + static_cast<FrameId>(options_.min_frames_between_keyframes) &&
                   mapper_idle;
  const bool c1c = inliers < reference_matches * 0.25 || need_close;
  const bool c2 = (inliers < reference_matches * ratio || need_close) && inliers > 15;
  return (c1a || c1b || c1c) && c2;
}

KeyframeId Tracker::CreateKeyframe(Frame* frame, bool all_depth_points, std::vector<int>* created,
                                   const std::vector<ErasedLandmark>* erased_as_dynamic) {
  std::vector<LandmarkId> judged_moving;  // Erased by this frame's dynamic votes: no new landmark.
  if (erased_as_dynamic != nullptr) {
    for (const ErasedLandmark& e : *erased_as_dynamic) judged_moving.push_back(e.seen.id);
    std::sort(judged_moving.begin(), judged_moving.end());
  }
  const FrameFeatures& f = *frame->features;
  // Keypoints with depth, nearest first.
  std::vector<int> by_depth;
  for (int i = 0; i < f.size(); ++i) {
    if (f.HasDepth(i)) by_depth.push_back(i);
  }
  std::stable_sort(by_depth.begin(), by_depth.end(),
                   [&f](int a, int b) { return f.depth(a) < f.depth(b); });
  // The bag of words outside the write lock (~0.25 ms the mapper would otherwise wait).
  const std::shared_ptr<const Vocabulary> vocabulary =
      map_->Read([](const MapData& map) { return map.shared_vocabulary(); });
  BowVector bow;
  if (vocabulary) bow = vocabulary->Transform(f.descriptors());
  const KeyframeId id = map_->Write([&](MapData& map) {
    const Rigid3d world_from_cam = frame->cam_from_world.Inverse();
    Keyframe kf;
    kf.frame_id = frame->id;
    kf.timestamp_s = frame->timestamp_s;
    kf.cam_from_world = frame->cam_from_world;
    kf.features = frame->features;
    kf.bow = std::move(bow);
    const KeyframeId kf_id = map.AddKeyframe(std::move(kf));
    for (size_t i = 0; i < frame->landmarks.size(); ++i) {
      const LandmarkId lm = frame->landmarks[i];
      if (lm == kNoLandmark || frame->outlier[i] || !map.HasLandmark(lm)) continue;
      if (map.landmark(lm).observations.count(kf_id) == 0)
        map.AddObservation(lm, kf_id, static_cast<int>(i));
    }
    int points = 0;
    for (int i : by_depth) {
      // A landmark the mapper culled since it was matched (parallel mode) leaves its keypoint
      // free for a new one; one this frame's dynamic votes erased does not (it was judged moving).
      const LandmarkId lm_id = frame->landmarks[i];
      const bool matched = lm_id != kNoLandmark && !frame->outlier[i] &&
                           (map.HasLandmark(lm_id) ||
                            std::binary_search(judged_moving.begin(), judged_moving.end(), lm_id));
      if (!matched) {
        Landmark lm;
        lm.point_in_world = world_from_cam * f.PointInCam(i, sensor_.camera);
        lm.first_keyframe = kf_id;
        lm.reference_keyframe = kf_id;
        lm.first_frame = frame->id;
        const LandmarkId lm_id = map.AddLandmark(std::move(lm));
        map.AddObservation(lm_id, kf_id, i);
        map.UpdateLandmarkGeometry(lm_id);
        map.UpdateLandmarkDescriptor(lm_id);
        frame->SetMatch(i, lm_id, map.landmark(lm_id).point_in_world);
        if (created != nullptr) created->push_back(i);
      }
      ++points;
      if (!all_depth_points && f.depth(i) > sensor_.th_depth_m && points > options_.new_close_points)
        break;
    }
    map.UpdateConnections(kf_id);
    return kf_id;
  });
  reference_keyframe_ = id;
  frame->reference_keyframe = id;
  last_keyframe_frame_ = frame->id;
  return id;
}

}  // namespace dynorb
