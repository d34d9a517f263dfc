// A bundle-adjustment problem copied out of the map: the solver's arrays (bundle_adjuster.h) with
// the ids they stand for, so that a result solved without the lock can be written back. Shared by
// the local BA (local_bundle_adjustment.h) and the global BA (loop_closing/).
#pragma once

#include <cstdint>
#include <vector>

#include "dynorb/map/map.h"
#include "dynorb/optimization/bundle_adjuster.h"

namespace dynorb {

struct BaSnapshot {
  uint64_t epoch = 0;  // MapData::correction_epoch at the snapshot
  std::vector<KeyframeId> keyframe_ids;
  std::vector<LandmarkId> landmark_ids;
  std::vector<BaKeyframe> keyframes;
  std::vector<Eigen::Vector3d> points;
  std::vector<BaObservation> observations;
  std::vector<int> keypoint_index;  // per observation: the keyframe's keypoint

  // Observation of landmark `landmark_index` by keyframe `keyframe_index` through `keypoint`.
  void AddObservation(const MapData& map, size_t keyframe_index, size_t landmark_index,
                      int keypoint);
};

// Erases from the map the observations the solve judged outliers (`inlier[o]` false), those
// that still link the same keyframe and keypoint to the landmark (fusion may have relinked the
// pair meanwhile). Returns how many were erased.
int EraseOutlierObservations(MapData* map, const BaSnapshot& snapshot,
                             const std::vector<bool>& inlier);

}  // namespace dynorb
