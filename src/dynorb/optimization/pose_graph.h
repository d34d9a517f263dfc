// Pose-graph optimisation (ORB-SLAM2's essential-graph step after a loop closure, in SE(3): an
// RGB-D map has metric scale). Each edge says how camera b sees camera a (b_from_a, measured
// before the loop was corrected, or after it for loop edges); the poses are moved so that all
// edges agree as well as possible, spreading a loop's correction along the graph.
// Residual of an edge: [translation; 2 * vector part of the quaternion] of
// measured_b_from_a^-1 * (b_cam_from_world * a_cam_from_world^-1), weighted by `weight`.
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include "dynorb/core/rigid3.h"

namespace dynorb {

struct PoseGraphEdge {
  uint64_t a = 0, b = 0;
  Rigid3d b_from_a;  // measured cam_b_from_cam_a
  double weight = 1.0;
};

struct PoseGraphOptions {
  int max_iterations = 20;
};

struct PoseGraphResult {
  double initial_cost = 0.0, final_cost = 0.0;
  int iterations = 0;
};

// Optimises the poses (cam_from_world) in place; poses in `fixed` stay; an edge naming a node
// that is not in `cam_from_world` is ignored. Deterministic (one thread).
PoseGraphResult OptimizePoseGraph(std::map<uint64_t, Rigid3d>* cam_from_world,
                                  const std::vector<PoseGraphEdge>& edges,
                                  const std::set<uint64_t>& fixed,
                                  const PoseGraphOptions& options = {});

}  // namespace dynorb
