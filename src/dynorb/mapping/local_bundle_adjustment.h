// Local bundle adjustment around a keyframe (ORB-SLAM2 Optimizer::LocalBundleAdjustment):
// free = the keyframe and its covisible keyframes, landmarks = all they observe, fixed = the other
// keyframes observing those landmarks. Runs as snapshot (read lock) -> solve (no lock) -> commit
// (write lock; entities erased in between are skipped; outlier observations are removed).
#pragma once

#include "dynorb/map/map.h"
#include "dynorb/mapping/mapper_options.h"

namespace dynorb {

struct LocalBaStats {
  int free_keyframes = 0;
  int fixed_keyframes = 0;
  int landmarks = 0;
  int observations = 0;
  int removed_observations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
};

LocalBaStats RunLocalBundleAdjustment(Map* map, KeyframeId keyframe, const RgbdSensor& sensor,
                                      const LocalMapperOptions& options);

}  // namespace dynorb
