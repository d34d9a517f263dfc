// Options of the local mapper (defaults: ORB-SLAM2's RGB-D values).
#pragma once

#include "dynorb/optimization/bundle_adjuster.h"

namespace dynorb {

struct LocalMapperOptions {
  int triangulation_neighbours = 10;     // Best covisibles searched for new landmarks.
  int fusion_neighbours = 10;            // Best covisibles (first ring) for fusion ...
  int fusion_second_neighbours = 5;      // ... and best covisibles of each (second ring).
  double fuse_radius_px = 3.0;           // Projection search radius (level 0) for fusion.
  int strict_max_distance = 50;          // Descriptor distance for fusion / triangulation (TH_LOW).
  double min_found_ratio = 0.25;         // Recent landmarks found in fewer frames than this
                                         // fraction of those that predicted them are culled.
  double redundant_ratio = 0.9;          // A keyframe whose close landmarks are this fraction
  int redundant_observers = 3;           // seen by >= this many other keyframes is culled.
  bool local_bundle_adjustment = true;
  // Local BA window (ORB-SLAM2 takes every covisible and observer). 20 / 20 since session 22
  // (10 / 10 before): the dynamic modes make more keyframes than a static scene needs, and a
  // 10-keyframe window spans too few frames there (docs/slam_core.md, "Local BA window").
  int local_ba_keyframes = 20;           // Free keyframes: the new one + its best covisibles.
  int local_ba_fixed_keyframes = 20;     // Fixed observers kept (most observations first).
  bool keyframe_culling = true;
  // A triangulated point seen at a keypoint without depth must not lie nearer than this fraction
  // of the nearest depth measured around that keypoint (it would occlude what the depth camera
  // saw there): rejects the garbage DLT gives for occlusion corners and mismatches, which, being
  // near, dominate the translation of every later pose. 0: off (ORB-SLAM2).
  double free_space_ratio = 0.8;
  BundleAdjusterOptions bundle_adjustment;

  void Validate() const;  // Throws InputError.
};

}  // namespace dynorb
