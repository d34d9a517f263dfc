// A timestamped camera trajectory: world_from_cam poses (the TUM convention), ordered by time.
#pragma once

#include <vector>

#include "dynorb/core/rigid3.h"

namespace dynorb {

struct StampedPose {
  double timestamp_s = 0.0;
  Rigid3d world_from_cam;
};

using Trajectory = std::vector<StampedPose>;

}  // namespace dynorb
