#include "dynorb/tracking/projection_search.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "dynorb/features/orb_matcher.h"

namespace dynorb {
namespace {

float AngleDelta(float a_deg, float b_deg) {
  float d = a_deg - b_deg;
  if (d < 0.0f) d += 360.0f;
  return d;
}

// Checks the virtual right coordinate of an RGB-D keypoint against the prediction.
bool RightCoordinateAgrees(const FrameFeatures& f, int index, double predicted_ur, double radius_px) {
  return f.u_right(index) < 0.0f || std::abs(predicted_ur - f.u_right(index)) <= radius_px;
}

}  // namespace

int SearchFromLastFrame(Frame* current, const Frame& last, const RgbdSensor& sensor, double radius_px,
                        const MatcherOptions& options) {
  const FrameFeatures& cf = *current->features;
  const ScaleLevels& levels = cf.levels();
  std::vector<int> matched_index;
  std::vector<float> deltas;
  std::vector<int> best_distance_of(cf.size(), std::numeric_limits<int>::max());
  std::vector<int> slot_of(cf.size(), -1);  // Current match slot of each keypoint.
  for (size_t i = 0; i < last.landmarks.size(); ++i) {
    if (last.landmarks[i] == kNoLandmark || last.outlier[i]) continue;
    const Eigen::Vector3d p = current->cam_from_world * last.landmark_points[i];
    if (p.z() <= 0.0) continue;
    const Eigen::Vector2d uv = sensor.camera.Project(p);
    if (!sensor.camera.InImage(uv)) continue;
    const int last_level = last.features->keypoint(static_cast<int>(i)).octave;
    const double radius = radius_px * levels.scale[last_level];
    const std::vector<int> candidates =
        cf.FeaturesInArea(uv.x(), uv.y(), radius, std::max(0, last_level - 1), last_level + 1);
    const uint8_t* descriptor = last.features->descriptor(static_cast<int>(i));
    const double predicted_ur = uv.x() - sensor.bf / p.z();
    int best = -1, best_distance = std::numeric_limits<int>::max();
    for (int c : candidates) {
      if (current->landmarks[c] != kNoLandmark) continue;
      if (!RightCoordinateAgrees(cf, c, predicted_ur, radius)) continue;
      const int d = HammingDistance256(descriptor, cf.descriptor(c));
      if (d < best_distance) {
        best_distance = d;
        best = c;
      }
    }
    if (best < 0 || best_distance > options.max_distance || best_distance >= best_distance_of[best]) continue;
    best_distance_of[best] = best_distance;
    if (slot_of[best] >= 0) matched_index[slot_of[best]] = -1;  // Superseded by a better match.
    slot_of[best] = static_cast<int>(matched_index.size());
    current->SetMatch(best, last.landmarks[i], last.landmark_points[i]);
    matched_index.push_back(best);
    deltas.push_back(AngleDelta(last.features->keypoint(static_cast<int>(i)).angle, cf.keypoint(best).angle));
  }
  const std::vector<bool> keep =
      options.check_orientation ? OrientationConsistent(deltas) : std::vector<bool>(deltas.size(), true);
  int count = 0;
  for (size_t m = 0; m < matched_index.size(); ++m) {
    if (matched_index[m] < 0) continue;
    if (keep[m]) {
      ++count;
    } else {
      current->landmarks[matched_index[m]] = kNoLandmark;
    }
  }
  return count;
}

int SearchLocalMap(Frame* current, const LocalMap& local, const RgbdSensor& sensor, double radius_factor,
                   const MatcherOptions& options, std::vector<LandmarkId>* visible) {
  const FrameFeatures& cf = *current->features;
  const ScaleLevels& levels = cf.levels();
  std::vector<LandmarkId> already(current->landmarks);
  std::sort(already.begin(), already.end());
  const Eigen::Vector3d center = current->cam_from_world.Inverse().translation;
  int count = 0;
  for (const LandmarkView& lm : local.landmarks) {
    if (std::binary_search(already.begin(), already.end(), lm.id)) continue;
    const Eigen::Vector3d p = current->cam_from_world * lm.point_in_world;
    if (p.z() <= 0.0) continue;
    const Eigen::Vector2d uv = sensor.camera.Project(p);
    if (!sensor.camera.InImage(uv)) continue;
    const Eigen::Vector3d ray = lm.point_in_world - center;
    const double distance = ray.norm();
    if (distance < 0.8 * lm.min_distance_m || distance > 1.2 * lm.max_distance_m) continue;
    const double view_cos = ray.dot(lm.normal_in_world) / distance;
    if (view_cos < 0.5) continue;
    if (visible != nullptr) visible->push_back(lm.id);
    const int level = PredictLevel(lm.max_distance_m, distance, levels);
    const double radius = radius_factor * (view_cos > 0.998 ? 2.5 : 4.0) * levels.scale[level];
    const std::vector<int> candidates = cf.FeaturesInArea(uv.x(), uv.y(), radius, std::max(0, level - 1), level);
    const double predicted_ur = uv.x() - sensor.bf / p.z();
    int best = -1, best_distance = 256, second_distance = 256, best_level = -1, second_level = -1;
    for (int c : candidates) {
      if (current->landmarks[c] != kNoLandmark && !current->outlier[c]) continue;
      if (!RightCoordinateAgrees(cf, c, predicted_ur, radius)) continue;
      const int d = HammingDistance256(lm.descriptor.data(), cf.descriptor(c));
      if (d < best_distance) {
        second_distance = best_distance;
        second_level = best_level;
        best_distance = d;
        best_level = cf.keypoint(c).octave;
        best = c;
      } else if (d < second_distance) {
        second_distance = d;
        second_level = cf.keypoint(c).octave;
      }
    }
    if (best < 0 || best_distance > options.max_distance) continue;
    if (best_level == second_level && best_distance > options.ratio * second_distance) continue;
    current->SetMatch(best, lm.id, lm.point_in_world);
    ++count;
  }
  return count;
}

std::vector<FrameLandmarkMatch> MatchByDescriptor(const FrameFeatures& frame, const Keyframe& keyframe,
                                                  const MapData& map, const MatcherOptions& options) {
  const FrameFeatures& kf = *keyframe.features;
  std::vector<int> kf_index;
  for (int i = 0; i < kf.size(); ++i) {
    if (keyframe.landmarks[i] != kNoLandmark && map.HasLandmark(keyframe.landmarks[i])) kf_index.push_back(i);
  }
  std::vector<FrameLandmarkMatch> matches;
  if (kf_index.empty() || frame.size() == 0) return matches;
  cv::Mat train(static_cast<int>(kf_index.size()), 32, CV_8U);
  for (size_t r = 0; r < kf_index.size(); ++r) std::memcpy(train.ptr(static_cast<int>(r)), kf.descriptor(kf_index[r]), 32);
  BruteForceMatchOptions bf;
  bf.max_distance = options.strict_max_distance;
  bf.max_ratio = options.brute_force_ratio;
  bf.mutual_check = true;
  const std::vector<DescriptorMatch> raw = MatchBruteForce(frame.descriptors(), train, bf);
  std::vector<float> deltas;
  for (const DescriptorMatch& m : raw) {
    deltas.push_back(AngleDelta(kf.keypoint(kf_index[m.train_index]).angle, frame.keypoint(m.query_index).angle));
  }
  const std::vector<bool> keep =
      options.check_orientation ? OrientationConsistent(deltas) : std::vector<bool>(deltas.size(), true);
  for (size_t m = 0; m < raw.size(); ++m) {
    if (!keep[m]) continue;
    const LandmarkId lm = keyframe.landmarks[kf_index[raw[m].train_index]];
    matches.push_back({raw[m].query_index, lm, map.landmark(lm).point_in_world});
  }
  return matches;
}

}  // namespace dynorb
