#include "dynorb/mapping/landmark_triangulator.h"

#include <cmath>
#include <limits>

#include "dynorb/core/angles.h"
#include "dynorb/features/orb_matcher.h"
#include "dynorb/geometry/two_view.h"
#include "dynorb/map/match_rules.h"
#include "dynorb/optimization/reprojection_cost.h"

namespace dynorb {
namespace {

const double kCosMinDltParallaxWithDepth = std::cos(DegToRad(5.0));

struct Candidate {
  int index1 = -1;
  int index2 = -1;
};

std::vector<Candidate> MatchForTriangulation(const Keyframe& kf1, const Keyframe& kf2, const Eigen::Matrix3d& f21,
                                             const LocalMapperOptions& options) {
  const FrameFeatures& f1 = *kf1.features;
  const FrameFeatures& f2 = *kf2.features;
  std::vector<int> free2;
  for (int j = 0; j < f2.size(); ++j) {
    if (kf2.landmarks[j] == kNoLandmark) free2.push_back(j);
  }
  std::vector<int> best_for2(f2.size(), -1), best_distance2(f2.size(), std::numeric_limits<int>::max());
  std::vector<Candidate> candidates;
  for (int i = 0; i < f1.size(); ++i) {
    if (kf1.landmarks[i] != kNoLandmark) continue;
    const cv::Point2f p1 = f1.keypoint(i).pt;
    const Eigen::Vector3d line = f21 * Eigen::Vector3d(p1.x, p1.y, 1.0);
    const double norm2 = line.x() * line.x() + line.y() * line.y();
    if (norm2 < 1e-18) continue;
    int best = -1, best_distance = options.strict_max_distance + 1;
    for (int j : free2) {
      const int d = HammingDistance256(f1.descriptor(i), f2.descriptor(j));
      if (d >= best_distance) continue;
      const cv::KeyPoint& k2 = f2.keypoint(j);
      const double num = line.x() * k2.pt.x + line.y() * k2.pt.y + line.z();
      if (num * num / norm2 >= 3.84 * f2.levels().sigma2[k2.octave]) continue;
      best = j;
      best_distance = d;
    }
    if (best < 0 || best_distance >= best_distance2[best]) continue;
    if (best_for2[best] >= 0) candidates[best_for2[best]].index1 = -1;  // Superseded.
    best_for2[best] = static_cast<int>(candidates.size());
    best_distance2[best] = best_distance;
    candidates.push_back({i, best});
  }
  std::vector<Candidate> unique;
  std::vector<float> deltas;
  for (const Candidate& c : candidates) {
    if (c.index1 < 0) continue;
    unique.push_back(c);
    float d = f1.keypoint(c.index1).angle - f2.keypoint(c.index2).angle;
    if (d < 0.0f) d += 360.0f;
    deltas.push_back(d);
  }
  const std::vector<bool> keep = OrientationConsistent(deltas);
  std::vector<Candidate> result;
  for (size_t k = 0; k < unique.size(); ++k) {
    if (keep[k]) result.push_back(unique[k]);
  }
  return result;
}

// False when keypoint `index` has no depth of its own and depth_m is less than `ratio` times
// the nearest surface the depth camera measured around it (a point there would have occluded
// it), or, with nothing measured around it, less than `ratio` times the frame's far depth (the
// camera would have measured a point that near: the keypoint looks beyond its range).
bool RespectsFreeSpace(const FrameFeatures& f, int index, double depth_m, double ratio) {
  if (ratio <= 0.0 || f.HasDepth(index)) return true;
  const double nearest = f.nearby_min_depth(index);
  const double bound = nearest > 0.0 ? nearest : f.far_depth();
  return depth_m >= ratio * bound;
}

bool ReprojectsWell(const RgbdSensor& sensor, const FrameFeatures& f, int index, const Eigen::Vector3d& point_in_cam) {
  const KeypointObservation obs = f.Observation(index);
  const double gate = obs.IsStereo() ? 7.8 : 5.991;
  return ReprojectionChi2(sensor.camera, sensor.bf, obs, point_in_cam) <= gate;
}

}  // namespace

std::vector<LandmarkId> TriangulateNewLandmarks(MapData* map, KeyframeId keyframe, const RgbdSensor& sensor,
                                                const LocalMapperOptions& options) {
  std::vector<LandmarkId> created;
  const PinholeCamera& cam = sensor.camera;
  const double baseline_m = sensor.bf / cam.fx;
  for (KeyframeId neighbour : map->BestCovisibles(keyframe, options.triangulation_neighbours)) {
    const Keyframe& kf1 = map->keyframe(keyframe);
    const Keyframe& kf2 = map->keyframe(neighbour);
    const Eigen::Vector3d center1 = kf1.CameraCenterInWorld(), center2 = kf2.CameraCenterInWorld();
    if ((center2 - center1).norm() < baseline_m) continue;
    const Eigen::Matrix3d f21 = FundamentalFromPoses(cam, kf1.cam_from_world, kf2.cam_from_world);
    const FrameFeatures& f1 = *kf1.features;
    const FrameFeatures& f2 = *kf2.features;
    const Rigid3d world_from_cam1 = kf1.cam_from_world.Inverse(), world_from_cam2 = kf2.cam_from_world.Inverse();
    const ScaleLevels& levels = f1.levels();
    for (const Candidate& c : MatchForTriangulation(kf1, kf2, f21, options)) {
      const cv::KeyPoint& k1 = f1.keypoint(c.index1);
      const cv::KeyPoint& k2 = f2.keypoint(c.index2);
      const Eigen::Vector2d n1((k1.pt.x - cam.cx) / cam.fx, (k1.pt.y - cam.cy) / cam.fy);
      const Eigen::Vector2d n2((k2.pt.x - cam.cx) / cam.fx, (k2.pt.y - cam.cy) / cam.fy);
      const Eigen::Vector3d ray1 = world_from_cam1.rotation * n1.homogeneous();
      const Eigen::Vector3d ray2 = world_from_cam2.rotation * n2.homogeneous();
      const double cos_rays = ray1.dot(ray2) / (ray1.norm() * ray2.norm());
      const bool stereo1 = f1.HasDepth(c.index1), stereo2 = f2.HasDepth(c.index2);
      const double cos_stereo1 = stereo1 ? std::cos(2.0 * std::atan2(baseline_m / 2.0, f1.depth(c.index1))) : 2.0;
      const double cos_stereo2 = stereo2 ? std::cos(2.0 * std::atan2(baseline_m / 2.0, f2.depth(c.index2))) : 2.0;
      const double cos_stereo = std::min(cos_stereo1, cos_stereo2);
      // Deviation from ORB-SLAM2: with depth on either side, DLT is used only beyond 5 degrees of
      // ray parallax. ORB-SLAM2 compares with the parallax of the virtual bf baseline (~7.5 cm),
      // which undervalues Kinect depth: at 3 m, a 0.15 m baseline gives ~8 cm DLT depth noise
      // against ~2 cm from the sensor (measured in local_mapper_test).
      const bool any_depth = stereo1 || stereo2;
      const double cos_needed = any_depth ? std::min(cos_stereo, kCosMinDltParallaxWithDepth) : cos_stereo;
      Eigen::Vector3d point;
      if (cos_rays < cos_needed && cos_rays > 0.0 && (any_depth || cos_rays < 0.9998)) {
        const auto x = TriangulateDlt(kf1.cam_from_world, n1, kf2.cam_from_world, n2);
        if (!x) continue;
        point = *x;
      } else if (stereo1 && cos_stereo1 <= cos_stereo2) {
        point = world_from_cam1 * f1.PointInCam(c.index1, cam);
      } else if (stereo2) {
        point = world_from_cam2 * f2.PointInCam(c.index2, cam);
      } else {
        continue;  // Too little parallax and no depth.
      }
      const Eigen::Vector3d p1 = kf1.cam_from_world * point, p2 = kf2.cam_from_world * point;
      if (p1.z() <= 0.0 || p2.z() <= 0.0) continue;
      if (!RespectsFreeSpace(f1, c.index1, p1.z(), options.free_space_ratio) ||
          !RespectsFreeSpace(f2, c.index2, p2.z(), options.free_space_ratio)) {
        continue;
      }
      if (!ReprojectsWell(sensor, f1, c.index1, p1) || !ReprojectsWell(sensor, f2, c.index2, p2)) continue;
      const double dist1 = (point - center1).norm(), dist2 = (point - center2).norm();
      if (dist1 <= 0.0 || dist2 <= 0.0) continue;
      const double ratio_dist = dist2 / dist1;
      const double ratio_octave = levels.scale[k1.octave] / levels.scale[k2.octave];
      const double ratio_factor = 1.5 * levels.scale_factor;
      if (ratio_dist * ratio_factor < ratio_octave || ratio_dist > ratio_octave * ratio_factor) continue;

      Landmark lm;
      lm.point_in_world = point;
      lm.first_keyframe = keyframe;
      lm.reference_keyframe = keyframe;
      lm.first_frame = kf1.frame_id;
      const LandmarkId id = map->AddLandmark(std::move(lm));
      map->AddObservation(id, keyframe, c.index1);
      map->AddObservation(id, neighbour, c.index2);
      map->UpdateLandmarkGeometry(id);
      map->UpdateLandmarkDescriptor(id);
      created.push_back(id);
    }
  }
  return created;
}

}  // namespace dynorb
