// Matching rules shared by tracking and mapping (ORB-SLAM2's ORBmatcher helpers).
// Pure functions; thread-safe.
#pragma once

#include <vector>

#include "dynorb/features/image_pyramid.h"

namespace dynorb {

// Orientation-consistency check: a histogram (30 bins) of the keypoint-angle change of each match;
// matches in the dominant bin are kept, and in the 2nd and 3rd bins when these hold more than
// 10 % of the dominant one. Returns one keep-flag per input angle change (degrees, [0, 360)).
std::vector<bool> OrientationConsistent(const std::vector<float>& angle_deltas_deg);

// Predicted pyramid level of a landmark seen from `distance_m`, given the largest distance at
// which it is still matchable at level 0 (clamped to the pyramid).
int PredictLevel(double max_distance_m, double distance_m, const ScaleLevels& levels);

}  // namespace dynorb
