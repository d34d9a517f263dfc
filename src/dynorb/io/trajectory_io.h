// Reading and writing trajectories in the TUM RGB-D format:
//   timestamp tx ty tz qx qy qz qw      (world_from_cam: camera position and orientation in world)
// '#' comment lines and blank lines are allowed; fields are separated by spaces, tabs or commas.
#pragma once

#include <string>

#include "dynorb/core/trajectory.h"

namespace dynorb {

struct TrajectoryReadOptions {
  // Require strictly increasing timestamps (duplicates and reordering are errors).
  bool require_increasing_timestamps = true;
  // Accept a pose whose timestamp equals the previous one and keep the later pose (TUM's
  // evaluate_ate.py/associate.py read into a dict, so the last line wins). Needed for the official
  // fr3/walking_static groundtruth.txt, which repeats 1341846251.4587. Decreasing stamps are still
  // rejected when require_increasing_timestamps is set.
  bool keep_last_of_duplicate_timestamps = false;
};

// Throws InputError naming file and line for: missing file, malformed line, NaN/Inf values, a
// quaternion far from unit norm (|q| not in [0.9, 1.1]), non-increasing timestamps, empty file.
Trajectory ReadTumTrajectory(const std::string& path, const TrajectoryReadOptions& options = {});

// Reads a dataset's ground-truth file (TUM groundtruth.txt): ReadTumTrajectory with
// keep_last_of_duplicate_timestamps = true, because official TUM files contain duplicate stamps.
Trajectory ReadTumGroundTruth(const std::string& path);

// Writes atomically with full double precision (timestamps to 1e-6 s, poses to 1e-9).
void WriteTumTrajectory(const std::string& path, const Trajectory& trajectory);
std::string FormatTumPoseLine(const StampedPose& pose);

}  // namespace dynorb
