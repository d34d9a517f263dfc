#include "dynorb/map/map.h"

#include "dynorb/features/orb_matcher.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace dynorb {

int MapData::WeightedObservations(LandmarkId lm) const {
  int weight = 0;
  for (const auto& [kf, index] : landmarks_.at(lm).observations) {
    weight += keyframes_.at(kf).features->HasDepth(index) ? 2 : 1;
  }
  return weight;
}

int MapData::NumTrackedLandmarks(KeyframeId kf, int min_weighted_observations) const {
  int count = 0;
  for (LandmarkId lm : keyframes_.at(kf).landmarks) {
    if (lm != kNoLandmark && WeightedObservations(lm) >= min_weighted_observations) ++count;
  }
  return count;
}

KeyframeId MapData::AddKeyframe(Keyframe keyframe) {
  keyframe.id = next_keyframe_id_++;
  keyframe.landmarks.assign(keyframe.features ? keyframe.features->size() : 0, kNoLandmark);
  if (vocabulary_ && keyframe.features) {
    if (keyframe.bow.empty())
      keyframe.bow = vocabulary_->Transform(keyframe.features->descriptors());
    database_.Add(keyframe.id, keyframe.bow);
  }
  const KeyframeId id = keyframe.id;
  keyframes_.emplace(id, std::move(keyframe));
  return id;
}

LandmarkId MapData::AddLandmark(Landmark landmark) {
  landmark.id = next_landmark_id_++;
  const LandmarkId id = landmark.id;
  landmarks_.emplace(id, std::move(landmark));
  return id;
}

void MapData::AddObservation(LandmarkId lm, KeyframeId kf, int index) {
  Keyframe& k = keyframes_.at(kf);
  k.landmarks.at(index) = lm;
  landmarks_.at(lm).observations[kf] = index;
}

void MapData::EraseObservation(LandmarkId lm, KeyframeId kf) {
  auto it = landmarks_.find(lm);
  if (it == landmarks_.end()) return;
  Landmark& l = it->second;
  auto obs = l.observations.find(kf);
  if (obs == l.observations.end()) return;
  keyframes_.at(kf).landmarks[obs->second] = kNoLandmark;
  l.observations.erase(obs);
  if (l.reference_keyframe == kf && !l.observations.empty()) l.reference_keyframe = l.observations.begin()->first;
  const bool single_without_depth =
      l.observations.size() == 1 &&
      !keyframes_.at(l.observations.begin()->first).features->HasDepth(l.observations.begin()->second);
  if (l.observations.empty() || single_without_depth) EraseLandmark(lm);
}

bool MapData::MoveLandmarkWithKeyframe(LandmarkId lm, const std::map<KeyframeId, Rigid3d>& before,
                                       const std::map<KeyframeId, Rigid3d>& after,
                                       KeyframeId follow) {
  Landmark& l = landmarks_.at(lm);
  KeyframeId ref = follow != kNoKeyframe ? follow : l.reference_keyframe;
  if (!HasKeyframe(ref)) {
    if (l.observations.empty()) return false;
    ref = l.observations.begin()->first;
  }
  l.point_in_world = after.at(ref).Inverse() * (before.at(ref) * l.point_in_world);
  return true;
}

void MapData::EraseLandmark(LandmarkId lm) {
  auto it = landmarks_.find(lm);
  if (it == landmarks_.end()) return;
  for (const auto& [kf, index] : it->second.observations) {
    Keyframe& k = keyframes_.at(kf);
    if (k.landmarks[index] == lm) k.landmarks[index] = kNoLandmark;
  }
  landmarks_.erase(it);
}

void MapData::ReplaceLandmark(LandmarkId from, LandmarkId into) {
  if (from == into || !HasLandmark(from) || !HasLandmark(into)) return;
  Landmark& src = landmarks_.at(from);
  Landmark& dst = landmarks_.at(into);
  for (const auto& [kf, index] : src.observations) {
    Keyframe& k = keyframes_.at(kf);
    if (dst.observations.count(kf) == 0) {
      k.landmarks[index] = into;
      dst.observations[kf] = index;
    } else if (k.landmarks[index] == from) {
      k.landmarks[index] = kNoLandmark;
    }
  }
  dst.num_visible += src.num_visible;
  dst.num_found += src.num_found;
  dst.dynamic_votes += src.dynamic_votes;
  src.observations.clear();
  landmarks_.erase(from);
  UpdateLandmarkDescriptor(into);
}

void MapData::UpdateLandmarkGeometry(LandmarkId lm) {
  Landmark& l = landmarks_.at(lm);
  if (l.observations.empty()) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const auto& [kf, index] : l.observations) {
    const Eigen::Vector3d dir = l.point_in_world - keyframes_.at(kf).CameraCenterInWorld();
    if (dir.norm() > 1e-9) normal += dir.normalized();
  }
  if (normal.norm() > 1e-9) l.normal_in_world = normal.normalized();
  const KeyframeId ref = HasKeyframe(l.reference_keyframe) && l.observations.count(l.reference_keyframe)
                             ? l.reference_keyframe
                             : l.observations.begin()->first;
  l.reference_keyframe = ref;
  const Keyframe& k = keyframes_.at(ref);
  const int level = k.features->keypoint(l.observations.at(ref)).octave;
  const ScaleLevels& levels = k.features->levels();
  const double distance = (l.point_in_world - k.CameraCenterInWorld()).norm();
  l.max_distance_m = distance * levels.scale[level];
  l.min_distance_m = l.max_distance_m / levels.scale[levels.NumLevels() - 1];
}

void MapData::UpdateLandmarkDescriptor(LandmarkId lm) {
  Landmark& l = landmarks_.at(lm);
  std::vector<const uint8_t*> descriptors;
  for (const auto& [kf, index] : l.observations) descriptors.push_back(keyframes_.at(kf).features->descriptor(index));
  if (descriptors.empty()) return;
  const size_t n = descriptors.size();
  int best_median = 1 << 30;
  size_t best = 0;
  std::vector<int> row(n);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < n; ++j) row[j] = HammingDistance256(descriptors[i], descriptors[j]);
    std::sort(row.begin(), row.end());
    const int median = row[(n - 1) / 2];
    if (median < best_median) {
      best_median = median;
      best = i;
    }
  }
  l.descriptor = cv::Mat(1, 32, CV_8U);
  std::memcpy(l.descriptor.data, descriptors[best], 32);
}

void MapData::UpdateConnections(KeyframeId kf, int min_weight) {
  Keyframe& k = keyframes_.at(kf);
  std::map<KeyframeId, int> counts;
  for (LandmarkId lm : k.landmarks) {
    if (lm == kNoLandmark) continue;
    for (const auto& [other, index] : landmarks_.at(lm).observations) {
      if (other != kf) ++counts[other];
    }
  }
  // Remove old edges on the other side (both its weights and its order: a keyframe no longer
  // covisible must not stay among the other's best covisibles, it may be erased later).
  for (const auto& [other, w] : k.covisibility) {
    auto it = keyframes_.find(other);
    if (it == keyframes_.end()) continue;
    it->second.covisibility.erase(kf);
    std::vector<KeyframeId>& order = it->second.ordered_covisibles;
    order.erase(std::remove(order.begin(), order.end(), kf), order.end());
  }
  k.covisibility.clear();
  if (counts.empty()) {
    k.ordered_covisibles.clear();
    return;
  }
  KeyframeId best = kNoKeyframe;
  int best_weight = -1;
  for (const auto& [other, w] : counts) {
    if (w > best_weight) {
      best_weight = w;
      best = other;
    }
    if (w >= min_weight) k.covisibility[other] = w;
  }
  if (k.covisibility.empty()) k.covisibility[best] = best_weight;
  auto order = [this](KeyframeId id) {
    Keyframe& kk = keyframes_.at(id);
    kk.ordered_covisibles.clear();
    for (const auto& [other, w] : kk.covisibility) kk.ordered_covisibles.push_back(other);
    std::stable_sort(kk.ordered_covisibles.begin(), kk.ordered_covisibles.end(),
                     [&kk](KeyframeId a, KeyframeId b) { return kk.covisibility.at(a) > kk.covisibility.at(b); });
  };
  for (const auto& [other, w] : k.covisibility) {
    keyframes_.at(other).covisibility[kf] = w;
    order(other);
  }
  order(kf);
  if (k.parent == kNoKeyframe && kf != keyframes_.begin()->first) {
    k.parent = k.ordered_covisibles.front();
    keyframes_.at(k.parent).children.insert(kf);
  }
}

std::vector<KeyframeId> MapData::BestCovisibles(KeyframeId kf, int n) const {
  const std::vector<KeyframeId>& all = keyframes_.at(kf).ordered_covisibles;
  return std::vector<KeyframeId>(all.begin(), all.begin() + std::min<size_t>(all.size(), n));
}

void MapData::EraseKeyframe(KeyframeId kf) {
  auto it = keyframes_.find(kf);
  if (it == keyframes_.end() || kf == keyframes_.begin()->first) return;
  database_.Erase(kf);
  Keyframe& k = it->second;
  for (const auto& [other, w] : k.covisibility) {
    Keyframe& o = keyframes_.at(other);
    o.covisibility.erase(kf);
    o.ordered_covisibles.erase(std::remove(o.ordered_covisibles.begin(), o.ordered_covisibles.end(), kf),
                               o.ordered_covisibles.end());
  }
  for (size_t i = 0; i < k.landmarks.size(); ++i) {
    if (k.landmarks[i] != kNoLandmark) EraseObservation(k.landmarks[i], kf);
  }
  // Re-parent children: to the parent of the erased keyframe (or its best covisible).
  KeyframeId new_parent = k.parent != kNoKeyframe ? k.parent : keyframes_.begin()->first;
  for (KeyframeId child : k.children) {
    Keyframe& c = keyframes_.at(child);
    c.parent = new_parent;
    keyframes_.at(new_parent).children.insert(child);
  }
  if (k.parent != kNoKeyframe) keyframes_.at(k.parent).children.erase(kf);
  erased_[kf] = {new_parent, k.cam_from_world * keyframes_.at(new_parent).cam_from_world.Inverse()};
  keyframes_.erase(it);
}

std::string MapData::FirstInconsistency() const {
  const auto kf_name = [](KeyframeId id) { return "keyframe " + std::to_string(id); };
  for (const auto& [id, k] : keyframes_) {
    for (size_t i = 0; i < k.landmarks.size(); ++i) {
      const LandmarkId lm = k.landmarks[i];
      if (lm == kNoLandmark) continue;
      const auto it = landmarks_.find(lm);
      if (it == landmarks_.end())
        return kf_name(id) + " refers to erased landmark " + std::to_string(lm);
      const auto obs = it->second.observations.find(id);
      if (obs == it->second.observations.end() || obs->second != static_cast<int>(i))
        return kf_name(id) + " keypoint " + std::to_string(i) + ": landmark " + std::to_string(lm) +
               " does not list it";
    }
    for (const auto& [other, w] : k.covisibility) {
      if (!HasKeyframe(other)) return kf_name(id) + " covisible with erased " + kf_name(other);
      if (keyframes_.at(other).covisibility.count(id) == 0)
        return kf_name(id) + " covisible with " + kf_name(other) + " but not the other way";
    }
    if (k.ordered_covisibles.size() != k.covisibility.size())
      return kf_name(id) + ": ordered covisibles differ from its covisibility";
    for (KeyframeId other : k.ordered_covisibles) {
      if (k.covisibility.count(other) == 0)
        return kf_name(id) + " orders " + kf_name(other) + " among its covisibles but has no edge";
    }
    if (k.parent != kNoKeyframe && !HasKeyframe(k.parent))
      return kf_name(id) + " has erased parent " + kf_name(k.parent);
    for (KeyframeId child : k.children) {
      if (!HasKeyframe(child) || keyframes_.at(child).parent != id)
        return kf_name(id) + " lists child " + kf_name(child) + " that is not its child";
    }
  }
  for (const auto& [lm, l] : landmarks_) {
    for (const auto& [kf, index] : l.observations) {
      if (!HasKeyframe(kf))
        return "landmark " + std::to_string(lm) + " observed by erased " + kf_name(kf);
      const Keyframe& k = keyframes_.at(kf);
      if (index < 0 || static_cast<size_t>(index) >= k.landmarks.size() || k.landmarks[index] != lm)
        return "landmark " + std::to_string(lm) + ": " + kf_name(kf) + " does not list it";
    }
  }
  return "";
}

Rigid3d MapData::ResolveKeyframePose(KeyframeId kf) const {
  Rigid3d cam_from_ancestor;  // Accumulated along the erased chain.
  KeyframeId current = kf;
  for (;;) {
    auto it = keyframes_.find(current);
    if (it != keyframes_.end()) return cam_from_ancestor * it->second.cam_from_world;
    const auto& [parent, cam_from_parent] = erased_.at(current);
    cam_from_ancestor = cam_from_ancestor * cam_from_parent;
    current = parent;
  }
}

}  // namespace dynorb
