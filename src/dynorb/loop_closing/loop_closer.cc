#include "dynorb/loop_closing/loop_closer.h"

#include <algorithm>

#include "dynorb/core/error.h"
#include "dynorb/core/timer.h"
#include "dynorb/map/place_candidates.h"
#include "dynorb/mapping/landmark_fuser.h"
#include "dynorb/optimization/pose_graph.h"
#include "dynorb/tracking/local_map.h"
#include "dynorb/tracking/projection_search.h"

namespace dynorb {
namespace {

bool Intersects(const std::set<KeyframeId>& a, const std::set<KeyframeId>& b) {
  for (KeyframeId k : a) {
    if (b.count(k)) return true;
  }
  return false;
}

}  // namespace

void LoopClosingOptions::Validate() const {
  if (!(min_agreement >= 0.0 && min_agreement <= 1.0))
    throw InputError("loop_closing: min_agreement must be in [0, 1]");
  if (min_keyframes < 2 || min_keyframes_between < 0 || consistency < 1 ||
      strong_covisibility < 1 || pose_graph_iterations < 1 || global_ba_iterations < 1) {
    throw InputError(
        "loop_closing: min_keyframes must be >= 2, min_keyframes_between >= 0, consistency >= 1, "
        "strong_covisibility >= 1, pose_graph_iterations >= 1 and global_ba_iterations >= 1");
  }
}

LoopCloser::LoopCloser(const RgbdSensor& sensor, const TrackerOptions& tracker_options,
                       const LocalMapperOptions& mapper_options, const LoopClosingOptions& options,
                       Map* map)
    : sensor_(sensor),
      tracker_options_(tracker_options),
      mapper_options_(mapper_options),
      options_((options.Validate(), options)),
      map_(map),
      relocalizer_(sensor, tracker_options) {}

LoopCloser::~LoopCloser() { JoinGlobalBa(); }

void LoopCloser::JoinGlobalBa() {
  if (global_ba_thread_.joinable()) global_ba_thread_.join();
}

void LoopCloser::WaitForGlobalBa() {
  JoinGlobalBa();
  global_ba_error_.Rethrow();
}

void LoopCloser::StopGlobalBa() {
  stop_global_ba_ = true;
  JoinGlobalBa();
  stop_global_ba_ = false;
  global_ba_error_.Rethrow();
}

std::vector<GlobalBaStats> LoopCloser::global_ba_stats() const {
  std::lock_guard<std::mutex> lock(global_ba_mutex_);
  return global_ba_stats_;
}

void LoopCloser::StartGlobalBa() {
  BundleAdjusterOptions ba = mapper_options_.bundle_adjustment;
  // The local BA's robust stage, then global_ba_iterations without the outliers.
  ba.second_iterations = options_.global_ba_iterations;
  ba.stop = &stop_global_ba_;
  const auto run = [this, ba] {
    const GlobalBaStats stats = RunGlobalBundleAdjustment(map_, sensor_, ba);
    std::lock_guard<std::mutex> lock(global_ba_mutex_);
    global_ba_stats_.push_back(stats);
  };
  if (options_.global_ba_thread) {
    global_ba_thread_ = std::thread([this, run] { global_ba_error_.Capture(run); });
  } else {
    run();
  }
}

std::vector<KeyframeId> LoopCloser::Detect(const MapData& map, KeyframeId keyframe) {
  std::vector<KeyframeId> enough;
  if (!map.HasKeyframe(keyframe) || map.vocabulary() == nullptr) return enough;
  if (static_cast<int>(map.NumKeyframes()) < options_.min_keyframes) return enough;
  if (last_loop_keyframe_ != kNoKeyframe &&
      keyframe < last_loop_keyframe_ + static_cast<KeyframeId>(options_.min_keyframes_between)) {
    return enough;
  }
  const Keyframe& k = map.keyframe(keyframe);
  if (k.covisibility.empty() || k.bow.empty()) return enough;
  // The least similar covisible keyframe sets the bar: a place outside the neighbourhood must look
  // at least as much like this view as the neighbourhood does.
  double min_score = 1.0;
  std::set<KeyframeId> excluded{keyframe};
  for (const auto& [other, weight] : k.covisibility) {
    excluded.insert(other);
    if (map.HasKeyframe(other))
      min_score = std::min(min_score, BowScore(k.bow, map.keyframe(other).bow));
  }
  // Keyframes the tracker inserted after this one (parallel mode) are its neighbours in time.
  for (auto it = map.keyframes().upper_bound(keyframe); it != map.keyframes().end(); ++it)
    excluded.insert(it->first);
  PlaceQueryOptions query;
  query.min_score = min_score;
  const std::vector<ScoredKeyframe> candidates = PlaceCandidates(map, k.bow, excluded, query);

  std::vector<Group> now;
  std::vector<bool> carried(groups_.size(), false);
  for (const ScoredKeyframe& c : candidates) {
    Group group;
    group.keyframes.insert(c.keyframe);
    for (const auto& [other, weight] : map.keyframe(c.keyframe).covisibility)
      group.keyframes.insert(other);
    bool consistent = false, counted = false;
    for (size_t g = 0; g < groups_.size(); ++g) {
      if (!Intersects(group.keyframes, groups_[g].keyframes)) continue;
      consistent = true;
      const int consistency = groups_[g].consistency + 1;
      if (!carried[g]) {
        now.push_back({group.keyframes, consistency});
        carried[g] = true;
      }
      if (consistency >= options_.consistency && !counted) {
        enough.push_back(c.keyframe);
        counted = true;
      }
    }
    if (!consistent) now.push_back({group.keyframes, 0});
  }
  groups_ = std::move(now);
  return enough;
}

double LoopCloser::Agreement(const MapData& map, const Frame& verified) const {
  Frame probe = verified;
  const int matched = probe.NumMatches();
  const LocalMap local = BuildLocalMap(map, probe, tracker_options_.max_local_keyframes);
  std::vector<LandmarkId> visible;
  SearchLocalMap(&probe, local, sensor_, tracker_options_.local_map_radius_factor,
                 tracker_options_.matcher, &visible);
  const int predicted = matched + static_cast<int>(visible.size());
  return predicted > 0 ? static_cast<double>(probe.NumMatches()) / predicted : 0.0;
}

LoopStepStats LoopCloser::ProcessOne(KeyframeId keyframe) {
  LoopStepStats stats;
  stats.keyframe = keyframe;
  if (!options_.enabled) return stats;
  Stopwatch watch;
  Frame verified;
  KeyframeId loop_keyframe = kNoKeyframe;
  std::vector<KeyframeId> candidates;
  uint64_t epoch = 0;  // of the map the verified pose was found in
  const auto verify = [&](const MapData& map) {
    epoch = map.correction_epoch();
    loop_keyframe = kNoKeyframe;
    if (!map.HasKeyframe(keyframe)) return;
    const Keyframe& k = map.keyframe(keyframe);
    for (KeyframeId candidate : candidates) {
      if (!map.HasKeyframe(candidate)) continue;
      Frame frame(k.frame_id, k.timestamp_s, k.features);
      frame.cam_from_world = k.cam_from_world;
      if (!relocalizer_.LocalizeAgainst(map, candidate, &frame)) continue;
      const double agreement = Agreement(map, frame);
      stats.agreement = std::max(stats.agreement, agreement);
      if (agreement < options_.min_agreement) continue;
      verified = std::move(frame);
      loop_keyframe = candidate;
      return;
    }
  };
  map_->Read([&](const MapData& map) {
    candidates = Detect(map, keyframe);
    if (candidates.empty()) return;
    stats.detected = true;
    verify(map);
  });
  if (loop_keyframe != kNoKeyframe) {
    StopGlobalBa();  // its result would be for the map before this loop
    // One that committed before it could be stopped moved the map under the verified pose: verify
    // again (no other thread corrects the map now).
    if (map_->Read([](const MapData& map) { return map.correction_epoch(); }) != epoch)
      map_->Read(verify);
  }
  if (loop_keyframe != kNoKeyframe) {
    map_->Correct([&](MapData& map) { Correct(&map, keyframe, loop_keyframe, verified, &stats); });
    if (stats.closed && options_.global_ba) StartGlobalBa();
  }
  stats.ms = watch.ElapsedMs();
  return stats;
}

void LoopCloser::Correct(MapData* map, KeyframeId keyframe, KeyframeId loop_keyframe,
                         const Frame& verified, LoopStepStats* stats) {
  if (!map->HasKeyframe(keyframe) || !map->HasKeyframe(loop_keyframe)) return;
  std::map<KeyframeId, Rigid3d> old_pose;
  for (const auto& [id, k] : map->keyframes()) old_pose[id] = k.cam_from_world;
  const Rigid3d keyframe_old = old_pose.at(keyframe);
  stats->correction_m =
      (keyframe_old.Inverse().translation - verified.cam_from_world.Inverse().translation).norm();
  stats->correction_deg =
      RotationAngleRad(keyframe_old.rotation * verified.cam_from_world.rotation.conjugate()) *
      180.0 / M_PI;

  // 1. The keyframe and its covisibles move rigidly to the verified pose, their landmarks with
  //    them; `moved_by` remembers which keyframe's move each landmark followed (step 4 continues
  //    from there, as ORB-SLAM2's mnCorrectedReference).
  std::vector<KeyframeId> connected{keyframe};
  for (const auto& [other, weight] : map->keyframe(keyframe).covisibility)
    connected.push_back(other);
  const std::set<KeyframeId> connected_set(connected.begin(), connected.end());
  std::map<KeyframeId, std::set<KeyframeId>> old_neighbours;
  std::map<KeyframeId, Rigid3d> corrected;
  for (KeyframeId id : connected) {
    corrected[id] = old_pose.at(id) * keyframe_old.Inverse() * verified.cam_from_world;
    for (const auto& [other, weight] : map->keyframe(id).covisibility)
      old_neighbours[id].insert(other);
  }
  std::map<LandmarkId, KeyframeId> moved_by;
  for (KeyframeId id : connected) {
    for (LandmarkId lm : map->keyframe(id).landmarks) {
      if (lm == kNoLandmark || !moved_by.emplace(lm, id).second) continue;
      Landmark& l = map->landmark(lm);
      l.point_in_world = corrected[id].Inverse() * (old_pose.at(id) * l.point_in_world);
    }
  }
  for (KeyframeId id : connected) map->keyframe(id).cam_from_world = corrected[id];

  // 2. Fuse: the verified matches, then the loop side's landmarks into every corrected keyframe.
  for (size_t i = 0; i < verified.landmarks.size(); ++i) {
    const LandmarkId loop_lm = verified.landmarks[i];
    if (loop_lm == kNoLandmark || verified.outlier[i] || !map->HasLandmark(loop_lm)) continue;
    const LandmarkId current = map->keyframe(keyframe).landmarks[i];
    if (current == loop_lm) continue;
    if (current != kNoLandmark) {
      map->ReplaceLandmark(current, loop_lm);
      ++stats->fused;
    } else if (map->landmark(loop_lm).observations.count(keyframe) == 0) {
      map->AddObservation(loop_lm, keyframe, static_cast<int>(i));
      ++stats->fused;
    }
  }
  // The loop side's landmarks (the loop keyframe's and its covisibles') into every corrected
  // keyframe (ORB-SLAM2's SearchAndFuse).
  std::vector<LandmarkId> loop_landmarks;
  {
    std::set<LandmarkId> seen;
    std::vector<KeyframeId> loop_side{loop_keyframe};
    for (const auto& [other, weight] : map->keyframe(loop_keyframe).covisibility) {
      if (!connected_set.count(other)) loop_side.push_back(other);
    }
    for (KeyframeId id : loop_side) {
      for (LandmarkId lm : map->keyframe(id).landmarks) {
        if (lm != kNoLandmark && seen.insert(lm).second) loop_landmarks.push_back(lm);
      }
    }
  }
  for (KeyframeId id : connected) {
    if (!map->HasKeyframe(id)) continue;
    const FuseStats fuse = FuseLandmarksInto(map, id, loop_landmarks, sensor_, mapper_options_);
    stats->fused += fuse.added_observations + fuse.merged;
  }
  for (KeyframeId id : connected) {
    if (map->HasKeyframe(id)) map->UpdateConnections(id);
  }
  const auto add_loop_edge = [&](KeyframeId a, KeyframeId b) {
    loop_edges_.insert({std::min(a, b), std::max(a, b)});
    map->keyframe(a).keep = true;  // the next loop's pose graph needs both ends
    map->keyframe(b).keep = true;
  };
  for (KeyframeId id : connected) {
    if (!map->HasKeyframe(id)) continue;
    std::vector<KeyframeId> new_links;
    for (const auto& [other, weight] : map->keyframe(id).covisibility) {
      if (!connected_set.count(other) && !old_neighbours[id].count(other))
        new_links.push_back(other);
    }
    for (KeyframeId other : new_links) add_loop_edge(id, other);
  }
  add_loop_edge(keyframe, loop_keyframe);

  // 3. Essential graph.
  std::map<uint64_t, Rigid3d> poses;
  for (const auto& [id, k] : map->keyframes()) poses[id] = k.cam_from_world;
  const std::map<uint64_t, Rigid3d> before = poses;
  const auto old_or_now = [&](KeyframeId id) {
    auto it = old_pose.find(id);
    return it != old_pose.end() ? it->second : before.at(id);
  };
  std::vector<PoseGraphEdge> edges;
  for (const auto& [id, k] : map->keyframes()) {
    if (k.parent != kNoKeyframe && map->HasKeyframe(k.parent)) {
      edges.push_back({k.parent, id, old_or_now(id) * old_or_now(k.parent).Inverse()});
    }
    for (const auto& [other, weight] : k.covisibility) {
      if (other >= id || weight < options_.strong_covisibility || other == k.parent ||
          k.children.count(other))
        continue;
      if (loop_edges_.count({other, id})) continue;
      edges.push_back({other, id, old_or_now(id) * old_or_now(other).Inverse()});
    }
  }
  for (const auto& [a, b] : loop_edges_) {
    if (map->HasKeyframe(a) && map->HasKeyframe(b))
      edges.push_back({a, b, before.at(b) * before.at(a).Inverse()});
  }
  PoseGraphOptions graph_options;
  graph_options.max_iterations = options_.pose_graph_iterations;
  OptimizePoseGraph(&poses, edges, {loop_keyframe}, graph_options);
  for (const auto& [id, pose] : poses) map->keyframe(id).cam_from_world = pose;

  // 4. Every landmark follows the keyframe it moved with in step 1, or else its reference keyframe.
  std::vector<LandmarkId> landmark_ids;
  for (const auto& [lm, l] : map->landmarks()) landmark_ids.push_back(lm);
  for (LandmarkId lm : landmark_ids) {
    const auto moved = moved_by.find(lm);
    if (map->MoveLandmarkWithKeyframe(lm, before, poses,
                                      moved != moved_by.end() ? moved->second : kNoKeyframe))
      map->UpdateLandmarkGeometry(lm);
  }
  map->NoteCorrection(std::move(old_pose));
  last_loop_keyframe_ = keyframe;
  stats->closed = true;
  stats->loop_keyframe = loop_keyframe;
  stats->inliers = verified.NumMatches();
}

}  // namespace dynorb
