// Global bundle adjustment: every keyframe pose and landmark of the map refined together, as
// ORB-SLAM2 runs after a loop correction (the pose graph moves keyframes as rigid bodies; the
// landmarks' own evidence is used only here). The first keyframe is fixed. Solved as the local BA
// (bundle_adjuster.h): a robust stage, then one without the observations beyond the chi^2 gate,
// which the commit erases from the map (ORB-SLAM2 keeps them; a map built among moving people
// holds many, session 40: docs/loop_closing.md).
//
// Runs as snapshot (read lock) -> solve (no lock, can be stopped) -> commit (write lock). What the
// mapper added in between follows the spanning tree: a keyframe missing from the snapshot moves
// as its nearest snapshot ancestor did, a landmark missing from it as its reference keyframe did.
// The commit is dropped when another correction (a new loop) changed the map in between. A commit
// is a correction of its own (MapData::NoteCorrection): the tracker re-anchors its last frame.
#pragma once

#include <atomic>
#include <vector>

#include "dynorb/map/map.h"
#include "dynorb/mapping/ba_snapshot.h"
#include "dynorb/mapping/mapper_options.h"
#include "dynorb/optimization/bundle_adjuster.h"

namespace dynorb {

struct GlobalBaStats {
  int keyframes = 0;
  int landmarks = 0;
  int observations = 0;
  int outlier_observations = 0;  // beyond the chi^2 gate after the robust stage or the final one
  int removed_observations = 0;  // of those, erased from the map by the commit
  int propagated_keyframes = 0;  // added after the snapshot, moved along the spanning tree
  int propagated_landmarks = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  bool committed = false;  // false: stopped, or the map was corrected again meanwhile
  double ms = 0.0;
};

// The three steps, for callers that hold the lock themselves (and for tests).
class GlobalBundleAdjustment {
 public:
  explicit GlobalBundleAdjustment(const MapData& map);  // The snapshot (caller holds a lock).
  // Without the lock. False if `options.stop` ended it (nothing to commit then).
  bool Solve(const RgbdSensor& sensor, const BundleAdjusterOptions& options);
  // Under the write lock. False (the map untouched) if it was not solved or the map was
  // corrected after the snapshot.
  bool Commit(MapData* map);
  const GlobalBaStats& stats() const { return stats_; }

 private:
  BaSnapshot snapshot_;
  BundleAdjusterResult result_;
  bool solved_ = false;
  GlobalBaStats stats_;
};

// Snapshot (read lock), solve, commit (write lock). `options.stop` (optional) ends the solve
// early; nothing is committed then.
GlobalBaStats RunGlobalBundleAdjustment(Map* map, const RgbdSensor& sensor,
                                        const BundleAdjusterOptions& options);

}  // namespace dynorb
