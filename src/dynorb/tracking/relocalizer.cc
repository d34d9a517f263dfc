#include "dynorb/tracking/relocalizer.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include <algorithm>

#include "dynorb/map/place_candidates.h"
#include "dynorb/optimization/pose_optimizer.h"
#include "dynorb/tracking/local_map.h"
#include "dynorb/tracking/projection_search.h"

namespace dynorb {
namespace {

constexpr int kMinMatches = 15;
constexpr int kMinInliers = 50;
// An RGB-D camera sees its map within metres: a pose that puts the median inlier landmark
// farther than this (or behind the camera) is a degenerate PnP solution, not a place.
constexpr double kMaxMedianDepthM = 100.0;

// Whether the frame's pose puts its matched landmarks where a depth camera could have seen them.
bool PlausibleDepths(const Frame& frame) {
  std::vector<double> depths;
  for (size_t i = 0; i < frame.landmarks.size(); ++i) {
    if (frame.landmarks[i] == kNoLandmark) continue;
    depths.push_back((frame.cam_from_world * frame.landmark_points[i]).z());
  }
  if (depths.empty()) return false;
  const auto middle = depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2);
  std::nth_element(depths.begin(), middle, depths.end());
  return *middle > 0.0 && *middle <= kMaxMedianDepthM;
}

int Optimize(const RgbdSensor& sensor, const PoseOptimizerOptions& options, Frame* frame) {
  std::vector<PoseObservation> observations;
  std::vector<int> index;
  for (size_t i = 0; i < frame->landmarks.size(); ++i) {
    if (frame->landmarks[i] == kNoLandmark) continue;
    observations.push_back({frame->landmark_points[i], frame->features->Observation(static_cast<int>(i))});
    index.push_back(static_cast<int>(i));
  }
  if (observations.size() < 3) return 0;
  const PoseOptimizerResult r = OptimizePose(sensor.camera, sensor.bf, observations, frame->cam_from_world, options);
  frame->cam_from_world = r.cam_from_world;
  for (size_t k = 0; k < index.size(); ++k) {
    if (!r.inlier[k]) frame->landmarks[index[k]] = kNoLandmark;
  }
  return r.num_inliers;
}

}  // namespace

std::vector<KeyframeId> Relocalizer::Candidates(const MapData& map,
                                                const FrameFeatures& features) const {
  std::vector<KeyframeId> candidates;
  if (map.vocabulary() != nullptr && options_.relocalization_place_candidates > 0) {
    const BowVector bow = map.vocabulary()->Transform(features.descriptors());
    for (const ScoredKeyframe& s : PlaceCandidates(map, bow)) {
      if (static_cast<int>(candidates.size()) >=
          std::min(options_.relocalization_place_candidates, options_.relocalization_candidates)) {
        break;
      }
      candidates.push_back(s.keyframe);
    }
  }
  for (auto it = map.keyframes().rbegin(); it != map.keyframes().rend(); ++it) {
    if (static_cast<int>(candidates.size()) >= options_.relocalization_candidates) break;
    if (std::find(candidates.begin(), candidates.end(), it->first) == candidates.end())
      candidates.push_back(it->first);
  }
  return candidates;
}

bool Relocalizer::Relocalize(const Map& map, Frame* frame) const {
  return map.Read([&](const MapData& data) {
    for (KeyframeId candidate : Candidates(data, *frame->features)) {
      if (LocalizeAgainst(data, candidate, frame)) return true;
    }
    frame->ResetMatches();
    return false;
  });
}

bool Relocalizer::LocalizeAgainst(const MapData& map, KeyframeId candidate, Frame* frame) const {
  frame->ResetMatches();
  const std::vector<FrameLandmarkMatch> matches =
      MatchByDescriptor(*frame->features, map.keyframe(candidate), map, options_.matcher);
  if (static_cast<int>(matches.size()) < kMinMatches) return false;

  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> image;
  for (const FrameLandmarkMatch& m : matches) {
    object.emplace_back(m.point_in_world.x(), m.point_in_world.y(), m.point_in_world.z());
    image.push_back(frame->features->keypoint(m.keypoint).pt);
  }
  cv::Mat k;
  cv::eigen2cv(sensor_.camera.K(), k);
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  cv::setRNGSeed(static_cast<int>((options_.seed * 1000003ULL + frame->id) & 0x7fffffff));  // Deterministic.
  const bool ok = cv::solvePnPRansac(object, image, k, cv::noArray(), rvec, tvec, false, 300, 4.0f, 0.99, inliers,
                                     cv::SOLVEPNP_EPNP);
  if (!ok || static_cast<int>(inliers.size()) < options_.min_frame_inliers) return false;
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  cv::cv2eigen(r, rotation);
  cv::cv2eigen(tvec, translation);
  frame->cam_from_world = Rigid3d(rotation, translation);
  for (int i : inliers) frame->SetMatch(matches[i].keypoint, matches[i].landmark, matches[i].point_in_world);

  int good = Optimize(sensor_, options_.pose, frame);
  if (good < options_.min_frame_inliers) return false;
  if (good < kMinInliers) {
    frame->reference_keyframe = candidate;
    const LocalMap local = BuildLocalMap(map, *frame, options_.max_local_keyframes);
    MatcherOptions wide = options_.matcher;
    SearchLocalMap(frame, local, sensor_, 10.0 / 2.5, wide);
    good = Optimize(sensor_, options_.pose, frame);
  }
  if (good < kMinInliers) return false;
  // Keypoints heaped on a few pixels without depth fit a camera 1e12 m away (review, session 54).
  if (!PlausibleDepths(*frame)) return false;
  frame->reference_keyframe = candidate;
  return true;
}

}  // namespace dynorb
