// Local bundle adjustment around a keyframe (ORB-SLAM2 Optimizer::LocalBundleAdjustment, with a
// bounded window): free = the keyframe and its best covisibles (local_ba_keyframes in total),
// landmarks = all they observe, fixed = the local_ba_fixed_keyframes other keyframes sharing most
// of those landmarks (ORB-SLAM2 takes every covisible and every observer, which in a room-sized
// map is the whole map at every keyframe). Runs as snapshot (read lock) -> solve (no lock) ->
// commit (write lock; entities erased in between are skipped; outlier observations are removed; the
// whole result is dropped if a correction, e.g. a global BA on its own thread, landed between).
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
  bool discarded = false;  // nothing written: the map was corrected between snapshot and commit,
                           // or the solve failed (BundleAdjusterResult::failed)
};

LocalBaStats RunLocalBundleAdjustment(Map* map, KeyframeId keyframe, const RgbdSensor& sensor,
                                      const LocalMapperOptions& options);

}  // namespace dynorb
